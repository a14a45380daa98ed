#include <gtest/gtest.h>
#include <petscsys.h>

#include "coapt/core/error.hpp"
#include "coapt/core/petsc.hpp"

namespace {

PetscErrorCode failing_call() {
  PetscFunctionBeginUser;
  SETERRQ(PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE, "value out of range");
}

TEST(PetscCheck, TurnsErrorCodeIntoExceptionNamingTheCall) {
  try {
    COAPT_PETSC_CHECK(failing_call());
    FAIL() << "no exception";
  } catch (const coapt::Error& e) {
    EXPECT_NE(std::string(e.what()).find("failing_call"), std::string::npos) << e.what();
  }
}

TEST(PetscHandle, DestroysAndMoves) {
  coapt::OwnedVec v;
  COAPT_PETSC_CHECK(VecCreateSeq(PETSC_COMM_SELF, 4, v.out()));
  EXPECT_TRUE(v);
  coapt::OwnedVec w(std::move(v));
  EXPECT_FALSE(v);
  PetscInt n = 0;
  COAPT_PETSC_CHECK(VecGetSize(w, &n));
  EXPECT_EQ(n, 4);
}

}  // namespace
