// Test driver shared by every test executable: initialises PETSc/MPI, lets every rank run
// the tests, prints from rank 0 only, and fails the run if any rank failed.
#include <gtest/gtest.h>
#include <mpi.h>

#include "coapt/core/context.hpp"
#include "coapt/core/log.hpp"

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  int exit_code = 0;
  {
    coapt::Context context(&argc, &argv);
    coapt::log::initialize(context.rank());
    coapt::log::set_level("warn");
    if (context.rank() != 0) {
      auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
      delete listeners.Release(listeners.default_result_printer());
    }
    const int local = RUN_ALL_TESTS();
    MPI_Allreduce(&local, &exit_code, 1, MPI_INT, MPI_MAX, context.comm());
  }
  return exit_code;
}
