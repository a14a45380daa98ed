#include "coapt/core/error.hpp"

#include <petscsys.h>

#include <string>

namespace coapt::detail {

void throw_petsc_error(int code, const char* call, const char* file, int line) {
  const char* text = nullptr;
  PetscErrorMessage(static_cast<PetscErrorCode>(code), &text, nullptr);
  throw Error(std::string("PETSc error ") + std::to_string(code) + " (" + (text ? text : "?") +
              ") in " + call + " at " + file + ":" + std::to_string(line));
}

}  // namespace coapt::detail
