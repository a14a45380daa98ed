#include "coapt/core/context.hpp"

#include <petscsys.h>

#include <cstring>

#include "coapt/core/error.hpp"

namespace coapt {

Context::Context(int* argc, char*** argv) {
  init(argc, argv);
}

Context::Context(const std::vector<std::string>& petsc_arguments) {
  // PetscInitialize keeps pointers into argv for the life of the program.
  static std::vector<std::string> storage;
  static std::vector<char*> pointers;
  storage.clear();
  storage.emplace_back("coapt");
  storage.insert(storage.end(), petsc_arguments.begin(), petsc_arguments.end());
  pointers.clear();
  for (auto& s : storage) pointers.push_back(s.data());
  pointers.push_back(nullptr);
  static int argc = 0;
  static char** argv = nullptr;
  argc = static_cast<int>(storage.size());
  argv = pointers.data();
  init(&argc, &argv);
}

void Context::init(int* argc, char*** argv) {
  COAPT_PETSC_CHECK(PetscInitialize(argc, argv, nullptr, nullptr));
  // coapt reports errors itself; PETSc's handler would print a trace to stderr on every rank.
  COAPT_PETSC_CHECK(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr));
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

Context::~Context() {
  PetscFinalize();
}

std::vector<std::string> Context::unused_petsc_options() {
  PetscInt n = 0;
  char** names = nullptr;
  char** values = nullptr;
  std::vector<std::string> unused;
  if (PetscOptionsLeftGet(nullptr, &n, &names, &values) != 0) return unused;
  for (PetscInt i = 0; i < n; ++i) {
    std::string entry = std::string("-") + names[i];
    if (values[i] && std::strlen(values[i]) > 0) entry += std::string(" ") + values[i];
    unused.push_back(entry);
  }
  PetscOptionsLeftRestore(nullptr, &n, &names, &values);
  return unused;
}

std::vector<std::string> split_petsc_arguments(int argc, char** argv, int& n_ours) {
  n_ours = argc;
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--") {
      n_ours = i;
      return std::vector<std::string>(argv + i + 1, argv + argc);
    }
  return {};
}

int rank_of(MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  return rank;
}

int size_of(MPI_Comm comm) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  return size;
}

}  // namespace coapt
