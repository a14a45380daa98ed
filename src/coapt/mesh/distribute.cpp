#include "coapt/mesh/distribute.hpp"

#include <metis.h>

#include <algorithm>
#include <numeric>
#include <string>

#include "coapt/core/context.hpp"
#include "coapt/core/error.hpp"

namespace coapt::mesh {
namespace {

template <class T>
MPI_Datatype mpi_type() {
  if constexpr (std::is_same_v<T, double>) return MPI_DOUBLE;
  if constexpr (std::is_same_v<T, int>) return MPI_INT;
  if constexpr (std::is_same_v<T, std::int64_t>) return MPI_INT64_T;
  if constexpr (std::is_same_v<T, PetscInt>) return MPIU_INT;
}

template <class T>
void send_vector(const std::vector<T>& data, int to, MPI_Comm comm) {
  const long long n = static_cast<long long>(data.size());
  MPI_Send(&n, 1, MPI_LONG_LONG, to, 0, comm);
  if (n > 0) MPI_Send(data.data(), static_cast<int>(n), mpi_type<T>(), to, 0, comm);
}

template <class T>
void receive_vector(std::vector<T>& data, int from, MPI_Comm comm) {
  long long n = 0;
  MPI_Recv(&n, 1, MPI_LONG_LONG, from, 0, comm, MPI_STATUS_IGNORE);
  data.resize(static_cast<std::size_t>(n));
  if (n > 0)
    MPI_Recv(data.data(), static_cast<int>(n), mpi_type<T>(), from, 0, comm, MPI_STATUS_IGNORE);
}

void broadcast_string(std::string& text, MPI_Comm comm) {
  int n = static_cast<int>(text.size());
  MPI_Bcast(&n, 1, MPI_INT, 0, comm);
  text.resize(static_cast<std::size_t>(n));
  if (n > 0) MPI_Bcast(text.data(), n, MPI_CHAR, 0, comm);
}

void broadcast_groups(std::vector<PhysicalGroup>& groups, MPI_Comm comm) {
  int n = static_cast<int>(groups.size());
  MPI_Bcast(&n, 1, MPI_INT, 0, comm);
  groups.resize(static_cast<std::size_t>(n));
  for (auto& g : groups) {
    broadcast_string(g.name, comm);
    int values[2] = {g.dim, g.tag};
    MPI_Bcast(values, 2, MPI_INT, 0, comm);
    g.dim = values[0];
    g.tag = values[1];
  }
}

/// Compressed vertex -> cells adjacency of a whole mesh.
struct VertexCells {
  std::vector<int> offsets, cells;
};

VertexCells vertex_cells(const Mesh& whole) {
  VertexCells adjacency;
  const int nv = whole.n_vertices(), nc = whole.n_cells(), k = whole.vertices_per_cell();
  adjacency.offsets.assign(static_cast<std::size_t>(nv) + 1, 0);
  for (int v : whole.cells) ++adjacency.offsets[static_cast<std::size_t>(v) + 1];
  std::partial_sum(adjacency.offsets.begin(), adjacency.offsets.end(), adjacency.offsets.begin());
  adjacency.cells.resize(whole.cells.size());
  std::vector<int> fill(adjacency.offsets.begin(), adjacency.offsets.end() - 1);
  for (int c = 0; c < nc; ++c)
    for (int a = 0; a < k; ++a)
      adjacency.cells[fill[whole.cells[static_cast<std::size_t>(c) * k + a]]++] = c;
  return adjacency;
}

/// This rank's part, built on rank 0 from the whole mesh and the partition.
Mesh extract_part(const Mesh& whole, const std::vector<int>& cell_part,
                  const std::vector<PetscInt>& cell_number, const std::vector<int>& vertex_owner,
                  const std::vector<PetscInt>& new_number, const std::vector<PetscInt>& offsets,
                  const VertexCells& adjacency, int part) {
  const int k = whole.vertices_per_cell(), dim = whole.dim;
  Mesh local;
  local.dim = dim;
  local.source = whole.source;
  local.vertex_offset = offsets[static_cast<std::size_t>(part)];
  local.n_global_vertices = offsets.back();
  local.n_global_cells = whole.n_cells();

  // Cells: owned (in source order), then the ghost layer (sharing a vertex), in source order.
  std::vector<int> owned_cells, ghost_cells;
  std::vector<char> is_local(static_cast<std::size_t>(whole.n_cells()), 0);
  for (int c = 0; c < whole.n_cells(); ++c)
    if (cell_part[c] == part) {
      owned_cells.push_back(c);
      is_local[c] = 1;
    }
  for (int c : owned_cells)
    for (int a = 0; a < k; ++a) {
      const int v = whole.cells[static_cast<std::size_t>(c) * k + a];
      for (int i = adjacency.offsets[v]; i < adjacency.offsets[v + 1]; ++i) {
        const int neighbour = adjacency.cells[i];
        if (!is_local[neighbour]) {
          is_local[neighbour] = 2;
          ghost_cells.push_back(neighbour);
        }
      }
    }
  std::sort(ghost_cells.begin(), ghost_cells.end());
  std::vector<int> cell_order = owned_cells;
  cell_order.insert(cell_order.end(), ghost_cells.begin(), ghost_cells.end());

  // Vertices: owned ones in global order, then ghosts in global order.
  std::vector<int> used;
  for (int c : cell_order)
    for (int a = 0; a < k; ++a) used.push_back(whole.cells[static_cast<std::size_t>(c) * k + a]);
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  std::stable_sort(used.begin(), used.end(), [&](int a, int b) {
    const bool owned_a = vertex_owner[a] == part, owned_b = vertex_owner[b] == part;
    if (owned_a != owned_b) return owned_a;
    return new_number[a] < new_number[b];
  });
  std::vector<int> local_index(static_cast<std::size_t>(whole.n_vertices()), -1);
  for (std::size_t i = 0; i < used.size(); ++i) {
    const int v = used[i];
    local_index[v] = static_cast<int>(i);
    if (vertex_owner[v] == part) ++local.n_owned_vertices;
    local.global_vertex.push_back(new_number[v]);
    local.original_vertex.push_back(whole.original_vertex[v]);
    for (int d = 0; d < dim; ++d)
      local.coordinates.push_back(whole.coordinates[static_cast<std::size_t>(v) * dim + d]);
  }

  std::vector<int> local_cell(static_cast<std::size_t>(whole.n_cells()), -1);
  for (std::size_t i = 0; i < cell_order.size(); ++i) {
    const int c = cell_order[i];
    local_cell[c] = static_cast<int>(i);
    for (int a = 0; a < k; ++a)
      local.cells.push_back(local_index[whole.cells[static_cast<std::size_t>(c) * k + a]]);
    local.cell_tags.push_back(whole.cell_tags[c]);
    local.original_cell.push_back(whole.original_cell[c]);
    local.global_cell.push_back(cell_number[c]);
  }
  local.n_owned_cells = static_cast<int>(owned_cells.size());

  for (int f = 0; f < whole.n_facets(); ++f) {
    const int c = whole.facet_cell[f];
    if (c < 0 || local_cell[c] < 0) continue;
    for (int a = 0; a < dim; ++a)
      local.facets.push_back(local_index[whole.facets[static_cast<std::size_t>(f) * dim + a]]);
    local.facet_tags.push_back(whole.facet_tags[f]);
    local.facet_cell.push_back(local_cell[c]);
  }
  return local;
}

void send_part(const Mesh& part, int to, MPI_Comm comm) {
  const long long header[6] = {part.dim,           part.n_owned_vertices,
                               part.vertex_offset, part.n_global_vertices,
                               part.n_owned_cells, part.n_global_cells};
  MPI_Send(header, 6, MPI_LONG_LONG, to, 0, comm);
  send_vector(part.coordinates, to, comm);
  send_vector(part.global_vertex, to, comm);
  send_vector(part.original_vertex, to, comm);
  send_vector(part.cells, to, comm);
  send_vector(part.cell_tags, to, comm);
  send_vector(part.original_cell, to, comm);
  send_vector(part.global_cell, to, comm);
  send_vector(part.facets, to, comm);
  send_vector(part.facet_tags, to, comm);
  send_vector(part.facet_cell, to, comm);
}

Mesh receive_part(MPI_Comm comm) {
  Mesh part;
  long long header[6] = {};
  MPI_Recv(header, 6, MPI_LONG_LONG, 0, 0, comm, MPI_STATUS_IGNORE);
  part.dim = static_cast<int>(header[0]);
  part.n_owned_vertices = static_cast<int>(header[1]);
  part.vertex_offset = static_cast<PetscInt>(header[2]);
  part.n_global_vertices = static_cast<PetscInt>(header[3]);
  part.n_owned_cells = static_cast<int>(header[4]);
  part.n_global_cells = header[5];
  receive_vector(part.coordinates, 0, comm);
  receive_vector(part.global_vertex, 0, comm);
  receive_vector(part.original_vertex, 0, comm);
  receive_vector(part.cells, 0, comm);
  receive_vector(part.cell_tags, 0, comm);
  receive_vector(part.original_cell, 0, comm);
  receive_vector(part.global_cell, 0, comm);
  receive_vector(part.facets, 0, comm);
  receive_vector(part.facet_tags, 0, comm);
  receive_vector(part.facet_cell, 0, comm);
  return part;
}

}  // namespace

std::vector<int> partition_cells(const Mesh& whole, int n_parts, Partitioner partitioner) {
  const int nc = whole.n_cells();
  std::vector<int> part(static_cast<std::size_t>(nc), 0);
  if (n_parts <= 1 || nc == 0) return part;
  if (nc < n_parts)
    throw InputError(whole.source + ": " + std::to_string(nc) + " cells cannot be shared by " +
                     std::to_string(n_parts) + " ranks");
  if (partitioner == Partitioner::blocks) {
    for (int c = 0; c < nc; ++c)
      part[c] = static_cast<int>(static_cast<long long>(c) * n_parts / nc);
    return part;
  }
  idx_t n_cells = nc, n_vertices = whole.n_vertices(), n_common = whole.dim, n_partitions = n_parts;
  idx_t objective = 0;
  const int k = whole.vertices_per_cell();
  std::vector<idx_t> offsets(static_cast<std::size_t>(nc) + 1);
  for (int c = 0; c <= nc; ++c) offsets[c] = static_cast<idx_t>(c) * k;
  std::vector<idx_t> indices(whole.cells.begin(), whole.cells.end());
  std::vector<idx_t> cell_part(static_cast<std::size_t>(nc)),
      vertex_part(static_cast<std::size_t>(n_vertices));
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 7;
  options[METIS_OPTION_NUMBERING] = 0;
  const int status = METIS_PartMeshDual(&n_cells, &n_vertices, offsets.data(), indices.data(),
                                        nullptr, nullptr, &n_common, &n_partitions, nullptr,
                                        options, &objective, cell_part.data(), vertex_part.data());
  if (status != METIS_OK)
    throw Error(whole.source + ": METIS could not partition the mesh (status " +
                std::to_string(status) + ")");
  std::copy(cell_part.begin(), cell_part.end(), part.begin());
  // METIS may leave a part empty on tiny meshes: fall back to blocks then.
  std::vector<int> counts(static_cast<std::size_t>(n_parts), 0);
  for (int p : part) ++counts[p];
  if (std::count(counts.begin(), counts.end(), 0) > 0)
    return partition_cells(whole, n_parts, Partitioner::blocks);
  return part;
}

Mesh distribute(const Mesh& whole, MPI_Comm comm, Partitioner partitioner) {
  const int rank = rank_of(comm), size = size_of(comm);
  Mesh local;
  // Errors found on rank 0 (e.g. too few cells) must reach every rank.
  std::string failure;
  if (rank == 0) {
    try {
      const auto cell_part = partition_cells(whole, size, partitioner);
      const int nv = whole.n_vertices(), k = whole.vertices_per_cell();
      std::vector<int> vertex_owner(static_cast<std::size_t>(nv), size);
      for (int c = 0; c < whole.n_cells(); ++c)
        for (int a = 0; a < k; ++a) {
          int& owner = vertex_owner[whole.cells[static_cast<std::size_t>(c) * k + a]];
          owner = std::min(owner, cell_part[c]);
        }
      // Vertices used by no cell are dropped; owned vertices are numbered rank by rank.
      std::vector<PetscInt> offsets(static_cast<std::size_t>(size) + 1, 0);
      for (int v = 0; v < nv; ++v)
        if (vertex_owner[v] < size) ++offsets[static_cast<std::size_t>(vertex_owner[v]) + 1];
      std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
      std::vector<PetscInt> next(offsets.begin(), offsets.end() - 1),
          new_number(static_cast<std::size_t>(nv), -1);
      for (int v = 0; v < nv; ++v)
        if (vertex_owner[v] < size) new_number[v] = next[vertex_owner[v]]++;
      // Cells are numbered rank by rank, in source order within a rank (extract_part's order).
      std::vector<PetscInt> cell_next(static_cast<std::size_t>(size) + 1, 0),
          cell_number(static_cast<std::size_t>(whole.n_cells()));
      for (const int p : cell_part) ++cell_next[static_cast<std::size_t>(p) + 1];
      std::partial_sum(cell_next.begin(), cell_next.end(), cell_next.begin());
      for (int c = 0; c < whole.n_cells(); ++c) cell_number[c] = cell_next[cell_part[c]]++;
      const auto adjacency = vertex_cells(whole);
      for (int p = size - 1; p >= 0; --p) {
        Mesh part = extract_part(whole, cell_part, cell_number, vertex_owner, new_number, offsets,
                                 adjacency, p);
        if (p == 0)
          local = std::move(part);
        else {
          int ok = 1;
          MPI_Send(&ok, 1, MPI_INT, p, 1, comm);
          send_part(part, p, comm);
        }
      }
    } catch (const Error& e) {
      failure = e.what();
      int ok = 0;
      for (int p = 1; p < size; ++p) MPI_Send(&ok, 1, MPI_INT, p, 1, comm);
    }
  } else {
    int ok = 0;
    MPI_Recv(&ok, 1, MPI_INT, 0, 1, comm, MPI_STATUS_IGNORE);
    if (ok) local = receive_part(comm);
  }
  broadcast_string(failure, comm);
  if (!failure.empty()) throw InputError(failure);
  local.source = whole.source;
  broadcast_string(local.source, comm);
  local.groups = whole.groups;
  broadcast_groups(local.groups, comm);
  local.comm = comm;
  return local;
}

}  // namespace coapt::mesh
