#pragma once
/// @file petsc.hpp
/// Small owners for PETSc objects: each destroys its object in its destructor.

#include <petscis.h>
#include <petscksp.h>
#include <petscmat.h>
#include <petscvec.h>

#include <utility>

namespace coapt {

/// Owns one PETSc object of type T (Vec, Mat, KSP, IS, ...), destroyed with Destroy.
template <class T, PetscErrorCode (*Destroy)(T*)>
class PetscHandle {
 public:
  PetscHandle() = default;
  /// Takes ownership of an existing object (may be null).
  explicit PetscHandle(T object) : object_(object) {}
  PetscHandle(const PetscHandle&) = delete;
  PetscHandle& operator=(const PetscHandle&) = delete;
  PetscHandle(PetscHandle&& other) noexcept : object_(std::exchange(other.object_, nullptr)) {}
  PetscHandle& operator=(PetscHandle&& other) noexcept {
    if (this != &other) {
      reset();
      object_ = std::exchange(other.object_, nullptr);
    }
    return *this;
  }
  ~PetscHandle() { reset(); }

  /// Destroys the owned object, if any.
  void reset() {
    if (object_) Destroy(&object_);
    object_ = nullptr;
  }
  /// The raw handle for PETSc calls; ownership stays here.
  T get() const { return object_; }
  operator T() const { return object_; }  // NOLINT: implicit on purpose, for PETSc calls
  /// Address for PETSc creation calls (XxxCreate(..., handle.out())); destroys any current object.
  T* out() {
    reset();
    return &object_;
  }
  explicit operator bool() const { return object_ != nullptr; }

 private:
  T object_ = nullptr;
};

using OwnedVec = PetscHandle<Vec, VecDestroy>;
using OwnedMat = PetscHandle<Mat, MatDestroy>;
using OwnedKSP = PetscHandle<KSP, KSPDestroy>;
using OwnedIS = PetscHandle<IS, ISDestroy>;
using OwnedVecScatter = PetscHandle<VecScatter, VecScatterDestroy>;

}  // namespace coapt
