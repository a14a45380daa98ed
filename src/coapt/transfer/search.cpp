/// @file search.cpp
/// Stages 1–2 of the transfer pipeline: master-cell exchange, box grid, pair list.

#include "coapt/transfer/search.hpp"

#include <chrono>
#include <cmath>
#include <cstring>
#include <numeric>

#include "coapt/core/error.hpp"
#include "coapt/transfer/intersection.hpp"

namespace coapt::transfer {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Tags of the point-to-point messages (on the exchange's own duplicate communicator).
constexpr int kTagCells = 1;
constexpr int kTagCoordinates = 2;

// Appends the bytes of `count` values to a message buffer / reads them back.
template <class T>
void put(std::vector<char>& buffer, const T* values, std::size_t count) {
  const std::size_t at = buffer.size();
  buffer.resize(at + count * sizeof(T));
  if (count) std::memcpy(buffer.data() + at, values, count * sizeof(T));
}
template <class T>
const char* get(const char* at, T* values, std::size_t count) {
  if (count) std::memcpy(values, at, count * sizeof(T));
  return at + count * sizeof(T);
}

// One face direction of the kernel's separating-plane test: face planes of `l` against the
// vertices of `s` (intersection.cpp, step 3: separated when max_k λ^L_j(s_k) ≤ tol).
template <int dim>
bool separated_by_faces_of(const Simplex<dim>& l, const Simplex<dim>& s) {
  for (int j = 0; j <= dim; ++j) {
    double highest = -std::numeric_limits<double>::infinity();
    for (int k = 0; k <= dim; ++k) {
      const double d = l.barycentric(j, s.vertices[k]);
      highest = d > highest ? d : highest;
    }
    if (!(highest > kPlaneTolerance)) return true;
  }
  return false;
}

}  // namespace

std::vector<int> face_neighbors(int dim, std::span<const int> cells, int n_vertices) {
  const int k = dim + 1;
  const std::size_t n_faces = cells.size();  // one per (cell, opposite vertex)
  std::vector<int> across(n_faces, -1);
  // Faces as sorted vertex tuples, bucketed by their smallest vertex (counting sort): the
  // cell across a face is the other cell with the same tuple, in the same bucket.
  struct Face {
    std::array<int, 2> rest{};  // the other vertices, ascending (dim = 2: rest[1] = -1)
    int id = 0;                 // c·k + i
  };
  std::vector<int> offsets(static_cast<std::size_t>(n_vertices) + 1, 0);
  std::vector<Face> faces(n_faces);
  auto face_of = [&](std::size_t id, int& lowest) {
    const std::size_t c = id / k;
    const int i = static_cast<int>(id % k);
    std::array<int, 3> v{-1, -1, -1};
    int n = 0;
    for (int a = 0; a < k; ++a)
      if (a != i) v[n++] = cells[c * k + a];
    // ascending, by hand (n ≤ 3)
    if (v[1] < v[0]) std::swap(v[0], v[1]);
    if (n == 3) {
      if (v[2] < v[1]) std::swap(v[1], v[2]);
      if (v[1] < v[0]) std::swap(v[0], v[1]);
    }
    lowest = v[0];
    return Face{{v[1], n == 3 ? v[2] : -1}, static_cast<int>(id)};
  };
  for (std::size_t id = 0; id < n_faces; ++id) {
    int lowest = 0;
    faces[id] = face_of(id, lowest);
    ++offsets[static_cast<std::size_t>(lowest) + 1];
  }
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  std::vector<Face> sorted(n_faces);
  {
    std::vector<int> fill(offsets.begin(), offsets.end() - 1);
    for (std::size_t id = 0; id < n_faces; ++id) {
      int lowest = 0;
      face_of(id, lowest);
      sorted[static_cast<std::size_t>(fill[static_cast<std::size_t>(lowest)]++)] = faces[id];
    }
  }
  // Within a bucket, sort by the other vertices: equal faces become adjacent (a bucket holds
  // tens of faces, so this beats comparing all pairs in it).
  for (int v = 0; v < n_vertices; ++v) {
    const auto begin = sorted.begin() + offsets[v], end = sorted.begin() + offsets[v + 1];
    std::sort(begin, end, [](const Face& a, const Face& b) { return a.rest < b.rest; });
    for (auto a = begin; a != end;) {
      auto b = a + 1;
      while (b != end && b->rest == a->rest) ++b;
      if (b - a == 2) {  // a face shared by exactly two cells
        across[static_cast<std::size_t>(a->id)] = (a + 1)->id / k;
        across[static_cast<std::size_t>((a + 1)->id)] = a->id / k;
      }
      a = b;
    }
  }
  return across;
}

template <int dim>
Box<dim> owned_cells_box(const mesh::Mesh& mesh) {
  Box<dim> box = Box<dim>::empty();
  for (int c = 0; c < mesh.n_owned_cells; ++c)
    for (int v : mesh.cell(c)) {
      Point<dim> x;
      for (int k = 0; k < dim; ++k) x[k] = mesh.coordinates[static_cast<std::size_t>(v) * dim + k];
      box.include(x);
    }
  return box;
}

template <int dim>
bool separated_by_face_plane(const Simplex<dim>& a, const Simplex<dim>& b) {
  if (a.degenerate() || b.degenerate()) return true;
  return separated_by_faces_of(a, b) || separated_by_faces_of(b, a);
}

// ================================================================================================
// Stage 1
// ================================================================================================

template <int dim>
void MasterExchange<dim>::exchange(const mesh::Mesh& master, MPI_Comm comm,
                                   std::span<const Box<dim>> slave_boxes, double margin) {
  COAPT_ASSERT(master.dim == dim, "master mesh of the wrong dimension");
  comm_ = comm;
  int rank = 0, size = 1;
  MPI_Comm_rank(comm_, &rank);
  MPI_Comm_size(comm_, &size);
  COAPT_ASSERT(static_cast<int>(slave_boxes.size()) == size, "one slave box per rank expected");

  // Every rank's (inflated) owned-master-cell box: tells each receiver whom to expect.
  Box<dim> own = owned_cells_box<dim>(master);
  if (!own.is_empty()) own = own.inflated(margin);
  std::vector<Box<dim>> master_boxes(static_cast<std::size_t>(size));
  MPI_Allgather(&own, 2 * dim, MPI_DOUBLE, master_boxes.data(), 2 * dim, MPI_DOUBLE, comm_);
  auto talks = [&](int source, int destination) {
    const Box<dim>& m = master_boxes[static_cast<std::size_t>(source)];
    const Box<dim>& s = slave_boxes[static_cast<std::size_t>(destination)];
    return !m.is_empty() && !s.is_empty() && m.overlaps(s);
  };

  // Cells per destination (a destination is any rank our master box reaches; it gets a
  // message even when no single cell reaches it, so receivers know what to expect).
  send_ranks_.clear();
  for (int r = 0; r < size; ++r)
    if (talks(rank, r)) send_ranks_.push_back(r);
  const std::size_t n_destinations = send_ranks_.size();
  std::vector<std::vector<int>> cells_to(n_destinations);
  for (int c = 0; c < master.n_owned_cells && n_destinations; ++c) {
    Box<dim> box = Box<dim>::empty();
    for (int v : master.cell(c)) {
      Point<dim> x;
      for (int k = 0; k < dim; ++k)
        x[k] = master.coordinates[static_cast<std::size_t>(v) * dim + k];
      box.include(x);
    }
    box = box.inflated(margin);
    for (std::size_t d = 0; d < n_destinations; ++d)
      if (box.overlaps(slave_boxes[static_cast<std::size_t>(send_ranks_[d])]))
        cells_to[d].push_back(c);
  }

  // Messages: [n_vertices, n_cells] [global numbers] [coordinates] [cells as message-local
  // vertex indices] [local cell numbers].
  send_offsets_.assign(1, 0);
  send_vertices_.clear();
  n_sent_cells_ = 0;
  std::vector<int> stamp(static_cast<std::size_t>(master.n_vertices()), -1);
  std::vector<int> message_index(static_cast<std::size_t>(master.n_vertices()), -1);
  std::vector<std::vector<char>> outgoing(n_destinations);
  std::vector<MPI_Request> requests(n_destinations);
  for (std::size_t d = 0; d < n_destinations; ++d) {
    const std::size_t first = send_vertices_.size();
    std::vector<int> cell_vertices;
    cell_vertices.reserve(cells_to[d].size() * (dim + 1));
    for (int c : cells_to[d])
      for (int v : master.cell(c)) {
        if (stamp[v] != static_cast<int>(d)) {
          stamp[v] = static_cast<int>(d);
          message_index[v] = static_cast<int>(send_vertices_.size() - first);
          send_vertices_.push_back(v);
        }
        cell_vertices.push_back(message_index[v]);
      }
    send_offsets_.push_back(static_cast<int>(send_vertices_.size()));
    const int header[2] = {static_cast<int>(send_vertices_.size() - first),
                           static_cast<int>(cells_to[d].size())};
    std::vector<PetscInt> globals;
    std::vector<double> coordinates;
    globals.reserve(static_cast<std::size_t>(header[0]));
    coordinates.reserve(static_cast<std::size_t>(header[0]) * dim);
    for (std::size_t i = first; i < send_vertices_.size(); ++i) {
      const int v = send_vertices_[i];
      globals.push_back(master.global_vertex[v]);
      for (int k = 0; k < dim; ++k)
        coordinates.push_back(master.coordinates[static_cast<std::size_t>(v) * dim + k]);
    }
    std::vector<char>& buffer = outgoing[d];
    put(buffer, header, 2);
    put(buffer, coordinates.data(), coordinates.size());
    put(buffer, globals.data(), globals.size());
    put(buffer, cell_vertices.data(), cell_vertices.size());
    put(buffer, cells_to[d].data(), cells_to[d].size());
    n_sent_cells_ += header[1];
    MPI_Isend(buffer.data(), static_cast<int>(buffer.size()), MPI_BYTE, send_ranks_[d], kTagCells,
              comm_, &requests[d]);
  }

  // Receive from every rank whose master box reaches our slave box, in rank order.
  recv_ranks_.clear();
  for (int r = 0; r < size; ++r)
    if (talks(r, rank)) recv_ranks_.push_back(r);
  struct Incoming {
    PetscInt global;
    int slot;
  };
  std::vector<Incoming> incoming;
  std::vector<double> incoming_coordinates;
  std::vector<int> incoming_cells;  // slots
  received_ = ReceivedMaster<dim>();
  recv_offsets_.assign(1, 0);
  std::vector<char> buffer;
  for (int source : recv_ranks_) {
    MPI_Status status;
    MPI_Probe(source, kTagCells, comm_, &status);
    int n_bytes = 0;
    MPI_Get_count(&status, MPI_BYTE, &n_bytes);
    buffer.resize(static_cast<std::size_t>(n_bytes));
    MPI_Recv(buffer.data(), n_bytes, MPI_BYTE, source, kTagCells, comm_, MPI_STATUS_IGNORE);
    int header[2];
    const char* at = get(buffer.data(), header, 2);
    const int first_slot = static_cast<int>(incoming.size());
    const std::size_t nv = static_cast<std::size_t>(header[0]),
                      nc = static_cast<std::size_t>(header[1]);
    incoming_coordinates.resize(incoming_coordinates.size() + nv * dim);
    at =
        get(at, incoming_coordinates.data() + static_cast<std::size_t>(first_slot) * dim, nv * dim);
    std::vector<PetscInt> globals(nv);
    at = get(at, globals.data(), nv);
    for (std::size_t i = 0; i < nv; ++i)
      incoming.push_back({globals[i], first_slot + static_cast<int>(i)});
    const std::size_t first_cell = incoming_cells.size();
    incoming_cells.resize(first_cell + nc * (dim + 1));
    at = get(at, incoming_cells.data() + first_cell, nc * (dim + 1));
    for (std::size_t i = first_cell; i < incoming_cells.size(); ++i)
      incoming_cells[i] += first_slot;
    const std::size_t first_id = received_.source_cell.size();
    received_.source_cell.resize(first_id + nc);
    get(at, received_.source_cell.data() + first_id, nc);
    received_.source_rank.insert(received_.source_rank.end(), nc, source);
    recv_offsets_.push_back(static_cast<int>(incoming.size()));
  }
  MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE);

  // Merge vertices sent by several ranks: received vertices sorted by global number.
  std::sort(incoming.begin(), incoming.end(), [](const Incoming& a, const Incoming& b) {
    return a.global < b.global || (a.global == b.global && a.slot < b.slot);
  });
  recv_position_.assign(incoming.size(), -1);
  for (std::size_t i = 0; i < incoming.size(); ++i) {
    if (i == 0 || incoming[i].global != incoming[i - 1].global) {
      received_.vertex_global.push_back(incoming[i].global);
      const double* x =
          incoming_coordinates.data() + static_cast<std::size_t>(incoming[i].slot) * dim;
      received_.coordinates.insert(received_.coordinates.end(), x, x + dim);
    }
    recv_position_[static_cast<std::size_t>(incoming[i].slot)] = received_.n_vertices() - 1;
  }
  received_.cells.resize(incoming_cells.size());
  for (std::size_t i = 0; i < incoming_cells.size(); ++i)
    received_.cells[i] = recv_position_[static_cast<std::size_t>(incoming_cells[i])];
}

template <int dim>
void MasterExchange<dim>::refresh(const mesh::Mesh& master) {
  const std::size_t n_destinations = send_ranks_.size();
  std::vector<std::vector<double>> outgoing(n_destinations);
  std::vector<MPI_Request> requests(n_destinations);
  for (std::size_t d = 0; d < n_destinations; ++d) {
    std::vector<double>& buffer = outgoing[d];
    buffer.reserve(static_cast<std::size_t>(send_offsets_[d + 1] - send_offsets_[d]) * dim);
    for (int i = send_offsets_[d]; i < send_offsets_[d + 1]; ++i)
      for (int k = 0; k < dim; ++k)
        buffer.push_back(master.coordinates[static_cast<std::size_t>(send_vertices_[i]) * dim + k]);
    MPI_Isend(buffer.data(), static_cast<int>(buffer.size()), MPI_DOUBLE, send_ranks_[d],
              kTagCoordinates, comm_, &requests[d]);
  }
  std::vector<double> buffer;
  for (std::size_t s = 0; s < recv_ranks_.size(); ++s) {
    const int first = recv_offsets_[s], n = recv_offsets_[s + 1] - first;
    buffer.resize(static_cast<std::size_t>(n) * dim);
    MPI_Recv(buffer.data(), n * dim, MPI_DOUBLE, recv_ranks_[s], kTagCoordinates, comm_,
             MPI_STATUS_IGNORE);
    for (int i = 0; i < n; ++i) {
      double* x =
          received_.coordinates.data() +
          static_cast<std::size_t>(recv_position_[static_cast<std::size_t>(first + i)]) * dim;
      for (int k = 0; k < dim; ++k) x[k] = buffer[static_cast<std::size_t>(i) * dim + k];
    }
  }
  MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
}

// ================================================================================================
// Stage 2
// ================================================================================================

template <int dim>
void BoxGrid<dim>::build(std::span<const Box<dim>> boxes) {
  Box<dim> all = Box<dim>::empty();
  Point<dim> mean_extent{};
  std::size_t n_boxes = 0;
  for (const Box<dim>& b : boxes) {
    if (b.is_empty()) continue;
    all.include(b);
    for (int k = 0; k < dim; ++k) mean_extent[k] += b.upper[k] - b.lower[k];
    ++n_boxes;
  }
  counts_.fill(1);
  origin_ = all.lower;
  inverse_size_.fill(0.0);
  bin_size_.fill(0.0);
  reach_.fill(0.0);
  if (n_boxes > 0) {
    // bin size: 1.5 mean extents, so that nearly every box of an even mesh is small (at
    // least 1e-9 of the domain, so flat sets stay finite)
    std::array<double, dim> n_bins{};
    double total = 1.0;
    for (int k = 0; k < dim; ++k) {
      const double extent = all.upper[k] - all.lower[k];
      const double size =
          std::max(1.5 * mean_extent[k] / static_cast<double>(n_boxes), 1e-9 * extent);
      n_bins[k] = extent > 0.0 ? std::max(1.0, std::floor(extent / size)) : 1.0;
      total *= n_bins[k];
    }
    const double limit = 2.0 * static_cast<double>(n_boxes) + 1.0;
    if (total > limit) {
      const double factor = std::pow(total / limit, 1.0 / dim);
      for (int k = 0; k < dim; ++k) n_bins[k] = std::max(1.0, std::floor(n_bins[k] / factor));
    }
    for (int k = 0; k < dim; ++k) {
      counts_[k] = static_cast<int>(n_bins[k]);
      const double extent = all.upper[k] - all.lower[k];
      inverse_size_[k] = extent > 0.0 ? counts_[k] / extent : 0.0;
      // a bin's width, rounded down a little: a box this small spans at most two bins
      bin_size_[k] = extent > 0.0 ? extent / counts_[k] * (1.0 - 1e-12) : 0.0;
      // a small box overlapping a query has lower ≥ query.lower − bin_size_ in exact
      // arithmetic; the slack covers the rounding of the differences
      const double magnitude = std::max(std::fabs(all.lower[k]), std::fabs(all.upper[k]));
      reach_[k] =
          bin_size_[k] * (1.0 + 1e-9) + 8.0 * std::numeric_limits<double>::epsilon() * magnitude;
    }
  }
  std::size_t n_total = 1;
  for (int k = 0; k < dim; ++k) n_total *= static_cast<std::size_t>(counts_[k]);
  const auto bin_of = [&](const Point<dim>& x) {
    int index = 0;
    for (int k = dim - 1; k >= 0; --k) index = index * counts_[k] + bin_coordinate(x[k], k);
    return index;
  };
  const auto is_small = [&](const Box<dim>& b) {
    for (int k = 0; k < dim; ++k)
      if (!(b.upper[k] - b.lower[k] <= bin_size_[k])) return false;
    return true;
  };

  // Small boxes: counting sort by the bin of the lower corner.
  small_offsets_.assign(n_total + 1, 0);
  std::size_t n_small = 0, n_large = 0;
  for (const Box<dim>& b : boxes) {
    if (b.is_empty()) continue;
    if (is_small(b)) {
      ++small_offsets_[static_cast<std::size_t>(bin_of(b.lower)) + 1];
      ++n_small;
    } else {
      ++n_large;
    }
  }
  std::partial_sum(small_offsets_.begin(), small_offsets_.end(), small_offsets_.begin());
  small_boxes_.resize(n_small);
  small_ids_.resize(n_small);
  large_boxes_.clear();
  large_ids_.clear();
  large_boxes_.reserve(n_large);
  large_ids_.reserve(n_large);
  {
    std::vector<int> fill(small_offsets_.begin(), small_offsets_.end() - 1);
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      const Box<dim>& b = boxes[i];
      if (b.is_empty()) continue;
      if (is_small(b)) {
        const int at = fill[static_cast<std::size_t>(bin_of(b.lower))]++;
        small_boxes_[static_cast<std::size_t>(at)] = b;
        small_ids_[static_cast<std::size_t>(at)] = static_cast<int>(i);
      } else {
        large_boxes_.push_back(b);
        large_ids_.push_back(static_cast<int>(i));
      }
    }
  }

  // Large boxes: listed in every bin they overlap (two passes: count, then fill).
  large_offsets_.clear();
  large_entries_.clear();
  if (n_large == 0) return;
  large_offsets_.assign(n_total + 1, 0);
  auto for_each_bin = [&](const Box<dim>& b, auto&& action) {
    std::array<int, dim> lo, hi, bin;
    for (int k = 0; k < dim; ++k) {
      lo[k] = bin_coordinate(b.lower[k], k);
      hi[k] = bin_coordinate(b.upper[k], k);
    }
    bin = lo;
    while (true) {
      int index = 0;
      for (int k = dim - 1; k >= 0; --k) index = index * counts_[k] + bin[k];
      action(index);
      int k = 0;
      while (k < dim && bin[k] == hi[k]) {
        bin[k] = lo[k];
        ++k;
      }
      if (k == dim) break;
      ++bin[k];
    }
  };
  for (const Box<dim>& b : large_boxes_)
    for_each_bin(b, [&](int index) { ++large_offsets_[index + 1]; });
  std::partial_sum(large_offsets_.begin(), large_offsets_.end(), large_offsets_.begin());
  large_entries_.resize(static_cast<std::size_t>(large_offsets_.back()));
  std::vector<int> fill(large_offsets_.begin(), large_offsets_.end() - 1);
  for (std::size_t i = 0; i < large_boxes_.size(); ++i)
    for_each_bin(large_boxes_[i],
                 [&](int index) { large_entries_[fill[index]++] = static_cast<int>(i); });
}

template <int dim>
PairSearch<dim>::PairSearch(const mesh::Mesh& slave, const mesh::Mesh& master,
                            const SearchOptions& options)
    : slave_(&slave), master_(&master), options_(options) {
  if (slave.dim != dim || master.dim != dim)
    throw InputError("transfer search: both meshes must have dimension " + std::to_string(dim));
  int compare = MPI_UNEQUAL;
  MPI_Comm_compare(slave.comm, master.comm, &compare);
  if (compare != MPI_IDENT && compare != MPI_CONGRUENT)
    throw InputError("transfer search: the slave and master meshes must share a communicator");
  if (!(options_.margin >= 0.0)) throw InputError("transfer search: the margin must be >= 0");
  MPI_Comm_dup(slave.comm, &comm_);
  if (options_.front)
    slave_neighbors_ = face_neighbors(
        dim,
        std::span<const int>(slave.cells.data(),
                             static_cast<std::size_t>(slave.n_owned_cells) * (dim + 1)),
        slave.n_vertices());
  full_search();
}

template <int dim>
PairSearch<dim>::~PairSearch() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized && comm_ != MPI_COMM_NULL) MPI_Comm_free(&comm_);
}

template <int dim>
void PairSearch<dim>::full_search() {
  auto start = std::chrono::steady_clock::now();
  int size = 1;
  MPI_Comm_size(comm_, &size);
  const Box<dim> own = owned_cells_box<dim>(*slave_);
  std::vector<Box<dim>> slave_boxes(static_cast<std::size_t>(size));
  MPI_Allgather(&own, 2 * dim, MPI_DOUBLE, slave_boxes.data(), 2 * dim, MPI_DOUBLE, comm_);
  exchange_.exchange(*master_, comm_, slave_boxes, options_.margin);
  reference_coordinates_ = master_->coordinates;
  statistics_ = SearchStatistics();
  statistics_.full = true;
  statistics_.exchange_seconds = seconds_since(start);
  statistics_.sent_master_cells = exchange_.n_sent_cells();
  statistics_.received_master_cells = exchange_.received().n_cells();
  build_grid();
  if (!options_.front) query_pairs();
}

template <int dim>
void PairSearch<dim>::build_grid() {
  auto start = std::chrono::steady_clock::now();
  const ReceivedMaster<dim>& received = exchange_.received();
  master_simplices_.resize(static_cast<std::size_t>(received.n_cells()));
  std::vector<Box<dim>> boxes(master_simplices_.size());
  for (int c = 0; c < received.n_cells(); ++c) {
    master_simplices_[c] = received.simplex(c);
    boxes[c] = Box<dim>::of(master_simplices_[c]).inflated(options_.margin);
  }
  grid_.build(boxes);
  if (options_.front)
    master_neighbors_ = face_neighbors(dim, received.cells, received.n_vertices());
  statistics_.grid_seconds = seconds_since(start);
}

template <int dim>
void PairSearch<dim>::query_pairs() {
  auto start = std::chrono::steady_clock::now();
  const mesh::Mesh& slave = *slave_;
  cell_pairs_.assign(static_cast<std::size_t>(slave.n_owned_cells), CellPairs{});
  for (auto& chunk : pair_chunks_) chunk.clear();  // keeps the capacity
  std::size_t chunk = 0;
  if (pair_chunks_.empty()) pair_chunks_.emplace_back();
  std::int64_t candidates = 0, n_pairs = 0;
  const bool inflated = options_.margin > 0.0;
  for (int c = 0; c < slave.n_owned_cells; ++c) {
    const Simplex<dim> s = cell_simplex<dim>(slave, c);
    if (s.degenerate()) continue;
    const Box<dim> box = Box<dim>::of(s);
    scratch_.clear();
    grid_.query(box, [&](int m) {
      const Simplex<dim>& t = master_simplices_[m];
      if (inflated && !Box<dim>::of(t).overlaps(box)) return;  // the grid holds inflated boxes
      ++candidates;
      if (!separated_by_face_plane(s, t)) scratch_.push_back(m);
    });
    store_pairs(c, chunk);
    n_pairs += static_cast<std::int64_t>(scratch_.size());
  }
  pair_chunks_.resize(chunk + 1);  // drops chunks a larger previous search needed
  statistics_.candidate_pairs = candidates;
  statistics_.pairs = n_pairs;
  finish_statistics();
  statistics_.query_seconds = seconds_since(start);
}

template <int dim>
void PairSearch<dim>::store_pairs(int c, std::size_t& chunk) {
  if (scratch_.empty()) return;
  // a cell's pairs never straddle two chunks
  if (pair_chunks_[chunk].size() + scratch_.size() >
      std::max(kChunk, pair_chunks_[chunk].capacity())) {
    ++chunk;
    if (chunk == pair_chunks_.size()) pair_chunks_.emplace_back();
    pair_chunks_[chunk].reserve(std::max(kChunk, scratch_.size()));
  } else if (pair_chunks_[chunk].capacity() == 0) {
    pair_chunks_[chunk].reserve(std::max(kChunk, scratch_.size()));
  }
  std::vector<int>& target = pair_chunks_[chunk];
  cell_pairs_[static_cast<std::size_t>(c)] = {
      static_cast<int>(chunk), static_cast<int>(target.size()), static_cast<int>(scratch_.size())};
  target.insert(target.end(), scratch_.begin(), scratch_.end());
}

template <int dim>
void PairSearch<dim>::finish_statistics() {
  const ReceivedMaster<dim>& received = exchange_.received();
  std::size_t chunk_bytes = 0;
  for (const auto& c : pair_chunks_) chunk_bytes += c.capacity() * sizeof(int);
  statistics_.memory_bytes = received.vertex_global.capacity() * sizeof(PetscInt) +
                             received.coordinates.capacity() * sizeof(double) +
                             (received.cells.capacity() + received.source_rank.capacity() +
                              received.source_cell.capacity()) *
                                 sizeof(int) +
                             master_simplices_.capacity() * sizeof(Simplex<dim>) +
                             grid_.memory_bytes() + cell_pairs_.capacity() * sizeof(CellPairs) +
                             chunk_bytes + reference_coordinates_.capacity() * sizeof(double) +
                             (slave_neighbors_.capacity() + master_neighbors_.capacity() +
                              visited_.capacity() + queue_.capacity()) *
                                 sizeof(int);
}

template <int dim>
double PairSearch<dim>::master_displacement() const {
  const std::vector<double>& x = master_->coordinates;
  if (x.size() != reference_coordinates_.size()) return std::numeric_limits<double>::infinity();
  double largest = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double d = std::fabs(x[i] - reference_coordinates_[i]);
    if (!(d <= largest)) largest = d;  // NaN propagates as "moved too far"
  }
  return largest;
}

template <int dim>
bool PairSearch<dim>::update_master(const mesh::Mesh& master) {
  master_ = &master;
  double moved = master_displacement();
  if (std::isnan(moved)) moved = std::numeric_limits<double>::infinity();
  MPI_Allreduce(MPI_IN_PLACE, &moved, 1, MPI_DOUBLE, MPI_MAX, comm_);
  if (!(moved <= options_.margin)) {
    full_search();
    return false;
  }
  auto start = std::chrono::steady_clock::now();
  exchange_.refresh(master);
  statistics_.full = false;
  statistics_.exchange_seconds = seconds_since(start);
  start = std::chrono::steady_clock::now();
  const ReceivedMaster<dim>& received = exchange_.received();
  for (int c = 0; c < received.n_cells(); ++c) master_simplices_[c] = received.simplex(c);
  statistics_.grid_seconds = seconds_since(start);  // grid itself kept
  if (!options_.front) query_pairs();
  return true;
}

template Box<2> owned_cells_box<2>(const mesh::Mesh&);
template Box<3> owned_cells_box<3>(const mesh::Mesh&);
template bool separated_by_face_plane<2>(const Simplex<2>&, const Simplex<2>&);
template bool separated_by_face_plane<3>(const Simplex<3>&, const Simplex<3>&);
template class MasterExchange<2>;
template class MasterExchange<3>;
template class BoxGrid<2>;
template class BoxGrid<3>;
template class PairSearch<2>;
template class PairSearch<3>;

}  // namespace coapt::transfer
