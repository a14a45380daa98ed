#pragma once
/// @file error.hpp
/// The exception family of coapt: every failure is a coapt::Error; what the user gave
/// wrong is an InputError, a solver that did not converge is a ConvergenceError.

#include <stdexcept>
#include <string>

namespace coapt {

/// Base of every exception coapt throws. The message is complete and user-facing.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Bad input: a file, key, value or mesh element. The message names it.
class InputError : public Error {
 public:
  using Error::Error;
};

/// A nonlinear or linear solver that did not converge; the time loop may recover.
class ConvergenceError : public Error {
 public:
  using Error::Error;
};

/// Internal invariant broken: a bug in coapt, not in the input.
class InternalError : public Error {
 public:
  using Error::Error;
};

namespace detail {
[[noreturn]] void throw_petsc_error(int code, const char* call, const char* file, int line);
}  // namespace detail

}  // namespace coapt

/// Checks a PETSc call and turns a non-zero error code into a coapt::Error naming the call.
#define COAPT_PETSC_CHECK(call)                                                         \
  do {                                                                                  \
    const int coapt_petsc_code_ = static_cast<int>(call);                               \
    if (coapt_petsc_code_ != 0)                                                         \
      ::coapt::detail::throw_petsc_error(coapt_petsc_code_, #call, __FILE__, __LINE__); \
  } while (false)

/// Checks an internal invariant (always on: cheap checks only).
#define COAPT_ASSERT(condition, message)                                                    \
  do {                                                                                      \
    if (!(condition))                                                                       \
      throw ::coapt::InternalError(std::string(__FILE__) + ":" + std::to_string(__LINE__) + \
                                   ": internal error: " + (message));                       \
  } while (false)

/// COAPT_ASSERT in builds without NDEBUG only: for an invariant that a proof guarantees, in
/// the innermost loop of a kernel, where the check costs a measurable share of the time. The
/// condition is not evaluated in a Release build (no side effects in it that the code needs).
#ifdef NDEBUG
#define COAPT_DEBUG_ASSERT(condition, message) \
  do {                                         \
  } while (false)
#else
#define COAPT_DEBUG_ASSERT(condition, message) COAPT_ASSERT(condition, message)
#endif
