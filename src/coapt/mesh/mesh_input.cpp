#include "coapt/mesh/mesh_input.hpp"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>

#include "coapt/core/collective.hpp"
#include "coapt/core/error.hpp"
#include "coapt/mesh/generators.hpp"
#include "coapt/mesh/gmsh_reader.hpp"

namespace coapt::mesh {

using config::Bounds;

void add_refinement_levels(MeshInput& input, int levels, const std::string& where) {
  if (levels == 0) return;
  if (input.type == "gmsh")
    throw InputError(
        fmt::format("{}: the mesh {} is read from a file and cannot be refined (use a "
                    ".geo file with type: geo)",
                    where, input.file));
  input.level += levels;
  for (auto& n : input.cells) n <<= levels;
}

MeshInput MeshInput::read(const config::Section& section, const std::string& case_directory) {
  MeshInput input;
  input.type = section.choice("type", "", {"rectangle", "box", "gmsh", "geo"},
                              {"", "where the mesh comes from"});
  input.level = section.get<int>(
      "level", 0,
      {"", "refinement level: each level halves the element size", Bounds::closed(0, 12)});
  const std::string partitioner = section.choice("partitioner", "metis", {"metis", "blocks"},
                                                 {"", "how cells are shared among the ranks"});
  input.partitioner = partitioner == "metis" ? Partitioner::metis : Partitioner::blocks;
  if (input.type == "gmsh" || input.type == "geo") {
    input.file = section.require<std::string>(
        "file",
        {"", "mesh (.msh, versions 2 and 4) or geometry (.geo) file, relative to the case file"});
    if (std::filesystem::path(input.file).is_relative())
      input.file = (std::filesystem::path(case_directory) / input.file).lexically_normal().string();
    if (input.type == "geo")
      input.size =
          section.require<double>("size", {"m", "element size at level 0", Bounds::positive()});
    else if (input.level != 0)
      section.fail(
          "level",
          "a mesh read from a file cannot be refined: use level 0, or a .geo file with type: geo");
    return input;
  }
  const int dim = input.type == "rectangle" ? 2 : 3;
  const std::vector<double> zero(static_cast<std::size_t>(dim), 0.0),
      one(static_cast<std::size_t>(dim), 1.0);
  input.lower = section.get<std::vector<double>>("lower", zero, {"m", "lower corner"});
  input.upper = section.get<std::vector<double>>("upper", one, {"m", "upper corner"});
  if (static_cast<int>(input.lower.size()) != dim)
    section.fail("lower", fmt::format("expected {} coordinates", dim));
  if (static_cast<int>(input.upper.size()) != dim)
    section.fail("upper", fmt::format("expected {} coordinates", dim));
  for (int d = 0; d < dim; ++d)
    if (!(input.upper[d] > input.lower[d]))
      section.fail("upper", "each coordinate must exceed the lower corner's");
  input.structured =
      section.get<bool>("structured", true,
                        {"", "structured (regular split of squares/cubes) or unstructured (Gmsh)"});
  if (input.structured) {
    const auto cells = section.get<std::vector<double>>(
        "cells", std::vector<double>(static_cast<std::size_t>(dim), 4.0),
        {"", "cells per direction at level 0", Bounds::closed(1, 1e6)});
    if (static_cast<int>(cells.size()) != dim)
      section.fail("cells", fmt::format("expected {} integers", dim));
    for (double n : cells) {
      if (std::floor(n) != n) section.fail("cells", "expected integers");
      input.cells.push_back(static_cast<int>(n) << input.level);
    }
  } else {
    input.size =
        section.require<double>("size", {"m", "element size at level 0", Bounds::positive()});
  }
  return input;
}

std::string MeshInput::describe() const {
  if (type == "gmsh") return "Gmsh file " + file;
  if (type == "geo")
    return fmt::format("{} meshed at size {:g} m", file, size / std::pow(2.0, level));
  std::string box;
  for (std::size_t d = 0; d < lower.size(); ++d)
    box += fmt::format("{}[{:g}, {:g}]", d ? " x " : "", lower[d], upper[d]);
  if (structured) {
    std::string n;
    for (std::size_t d = 0; d < cells.size(); ++d) n += fmt::format("{}{}", d ? "x" : "", cells[d]);
    return fmt::format("{} {}, {} cells, structured, level {}", type, box, n, level);
  }
  return fmt::format("{} {}, unstructured at size {:g} m, level {}", type, box,
                     size / std::pow(2.0, level), level);
}

Mesh load_mesh(const MeshInput& input, MPI_Comm comm, QualityReport* report) {
  Mesh whole;
  QualityReport quality;
  run_on_root(comm, [&] {
    const double h = input.size / std::pow(2.0, input.level);
    if (input.type == "gmsh") {
      whole = read_gmsh(input.file);
    } else if (input.type == "geo") {
      // Gmsh caps sizes at MeshSizeMax, then multiplies them by MeshSizeFactor: cap at the
      // level-0 size and scale by 2^-level, so every size (local ones too) halves per level.
      whole = mesh_geo_file(input.file, input.size, std::pow(0.5, input.level));
    } else if (input.type == "rectangle") {
      whole = input.structured
                  ? structured_rectangle(input.lower[0], input.lower[1], input.upper[0],
                                         input.upper[1], input.cells[0], input.cells[1])
                  : unstructured_rectangle(input.lower[0], input.lower[1], input.upper[0],
                                           input.upper[1], h);
    } else {
      whole = input.structured
                  ? structured_box(input.lower[0], input.lower[1], input.lower[2], input.upper[0],
                                   input.upper[1], input.upper[2], input.cells[0], input.cells[1],
                                   input.cells[2])
                  : unstructured_box(input.lower[0], input.lower[1], input.lower[2], input.upper[0],
                                     input.upper[1], input.upper[2], h);
    }
    orient_cells(whole);
    quality = check_quality(whole);
    require_valid(whole, quality);
  });
  if (report) {
    *report = quality;  // complete on rank 0; other ranks get the summary figures below
    double figures[4] = {quality.min_measure, quality.max_measure, quality.min_shape,
                         quality.max_shape};
    MPI_Bcast(figures, 4, MPI_DOUBLE, 0, comm);
    long long n_cells = static_cast<long long>(quality.n_cells);
    MPI_Bcast(&n_cells, 1, MPI_LONG_LONG, 0, comm);
    report->min_measure = figures[0];
    report->max_measure = figures[1];
    report->min_shape = figures[2];
    report->max_shape = figures[3];
    report->n_cells = n_cells;
  }
  return distribute(whole, comm, input.partitioner);
}

}  // namespace coapt::mesh
