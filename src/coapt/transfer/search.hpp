#pragma once
/// @file search.hpp
/// Parallel search of the element pairs of the variational transfer (stages 1–2 of the
/// pipeline; the local integrals are intersection.hpp, the operators operators.hpp).
///
/// The slave mesh S (the fluid: it carries the multiplier) and the master mesh M (the solid)
/// are distributed over the same communicator independently: any partition, not aligned.
/// Every pair (owned slave cell, master cell) whose intersection may have positive measure is
/// found on the rank that owns the slave cell, so each pair is seen exactly once.
///
///  Stage 1, MasterExchange: every rank publishes (allgather) the bounding box of its owned
///    slave cells and of its owned master cells. Each rank sends every owned master cell
///    (vertex coordinates and global vertex numbers) to each rank whose slave box overlaps
///    the cell's box, and receives the master cells it needs, from the ranks whose master box
///    overlaps its slave box only (point-to-point, no all-to-all). Vertices are sent once per
///    destination and merged on arrival (received vertices sorted by global number).
///  Stage 2, BoxGrid + PairSearch: a uniform grid over the received master cells' boxes; for
///    each owned slave cell the grid yields the master cells whose box overlaps the slave
///    cell's box, and a separating-plane test (the intersection kernel's own first test, with
///    the same tolerance, so it never drops a pair the kernel would keep) discards most of
///    the box overlaps that do not intersect. The pairs are stored grouped by slave cell.
///  Stage 2 by advancing front (SearchOptions::front, what the operators use): no pair list
///    is made up front; sweep() walks the owned slave cells and, for each, the received
///    master cells through their face neighbours, starting from one of the cells an earlier
///    face neighbour of the slave cell overlaps, with the caller's test (the intersection
///    kernel itself) deciding which faces of which cells the front crosses. Cells it cannot
///    vouch for fall back to the grid (see sweep()).
///
/// Moving master (the solid moves through a fixed fluid mesh): the search is built with the
/// master boxes inflated by `SearchOptions::margin`. While no master vertex has moved more
/// than the margin (per coordinate) from where it was at the last full search, the exchange
/// pattern and the grid stay valid (Verlet-list argument: every current box lies inside its
/// inflated reference box), so update_master() only re-sends the coordinates along the
/// existing pattern, re-makes the master simplices and re-runs the per-slave-cell queries.
/// Past the margin (on any rank) it redoes the whole search. The slave never moves here; if
/// it does, build a new PairSearch.
///
/// Memory per rank: received master cells (dim + 1 ints) and vertices (global number and
/// coordinates), one Simplex per received master cell, the grid (a few ints per received
/// cell), one int per pair, and three ints per owned slave cell; with the front, dim + 1
/// face neighbours per owned slave cell and per received master cell, and one int per
/// received master cell (the front's marks).

#include <mpi.h>
#include <petscsys.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "coapt/core/error.hpp"
#include "coapt/mesh/mesh.hpp"
#include "coapt/transfer/geometry.hpp"
#include "coapt/transfer/intersection.hpp"

namespace coapt::transfer {

/// A closed axis-aligned box; empty when lower > upper on some axis.
template <int dim>
struct Box {
  Point<dim> lower;
  Point<dim> upper;

  static Box empty() {
    Box b;
    b.lower.fill(std::numeric_limits<double>::infinity());
    b.upper.fill(-std::numeric_limits<double>::infinity());
    return b;
  }
  static Box of(const Simplex<dim>& s) { return Box{s.box_lower, s.box_upper}; }
  bool is_empty() const {
    for (int k = 0; k < dim; ++k)
      if (!(lower[k] <= upper[k])) return true;
    return false;
  }
  void include(const Point<dim>& p) {
    for (int k = 0; k < dim; ++k) {
      lower[k] = std::min(lower[k], p[k]);
      upper[k] = std::max(upper[k], p[k]);
    }
  }
  void include(const Box& other) {
    for (int k = 0; k < dim; ++k) {
      lower[k] = std::min(lower[k], other.lower[k]);
      upper[k] = std::max(upper[k], other.upper[k]);
    }
  }
  Box inflated(double margin) const {
    Box b = *this;
    for (int k = 0; k < dim; ++k) {
      b.lower[k] -= margin;
      b.upper[k] += margin;
    }
    return b;
  }
  /// Closed boxes: touching counts as overlapping (as in the intersection kernel's test).
  bool overlaps(const Box& other) const {
    for (int k = 0; k < dim; ++k)
      if (upper[k] < other.lower[k] || other.upper[k] < lower[k]) return false;
    return true;
  }
  bool contains(const Box& other) const {
    for (int k = 0; k < dim; ++k)
      if (other.lower[k] < lower[k] || upper[k] < other.upper[k]) return false;
    return true;
  }
};

/// The simplex of local cell `c` of `mesh` (make_simplex on its vertex coordinates).
template <int dim>
Simplex<dim> cell_simplex(const mesh::Mesh& mesh, int c) {
  std::array<Point<dim>, dim + 1> vertices;
  const int* cell = mesh.cells.data() + static_cast<std::size_t>(c) * (dim + 1);
  for (int v = 0; v <= dim; ++v) {
    const double* x = mesh.coordinates.data() + static_cast<std::size_t>(cell[v]) * dim;
    for (int k = 0; k < dim; ++k) vertices[v][k] = x[k];
  }
  return make_simplex<dim>(vertices);
}

/// Bounding box of the owned cells of `mesh` (empty if it owns none).
template <int dim>
Box<dim> owned_cells_box(const mesh::Mesh& mesh);

/// True when some face plane of `a` or of `b` separates them, with the intersection kernel's
/// tolerance and arithmetic (all λ ≤ kPlaneTolerance): such pairs have an intersection of zero
/// measure and local_integrals() returns false for them. The converse does not hold (3D pairs
/// separated only by an edge–edge plane pass), so this is a conservative filter. Degenerate
/// simplices count as separated.
template <int dim>
bool separated_by_face_plane(const Simplex<dim>& a, const Simplex<dim>& b);

// ------------------------------------------------------------------------------------------
// Stage 1: exchange of master cells
// ------------------------------------------------------------------------------------------

/// The master cells a rank received (its own included, when they overlap its slave box).
template <int dim>
struct ReceivedMaster {
  std::vector<PetscInt> vertex_global;  ///< master global vertex number, ascending, unique
  std::vector<double> coordinates;      ///< per received vertex, dim values [m]
  std::vector<int> cells;               ///< per received cell, dim + 1 received-vertex indices
  std::vector<int> source_rank;         ///< rank that owns each received cell
  std::vector<int> source_cell;         ///< its local (owned) cell index on that rank

  int n_cells() const { return static_cast<int>(source_rank.size()); }
  int n_vertices() const { return static_cast<int>(vertex_global.size()); }
  /// Simplex of received cell `c` from the current coordinates.
  Simplex<dim> simplex(int c) const {
    std::array<Point<dim>, dim + 1> vertices;
    for (int v = 0; v <= dim; ++v) {
      const double* x =
          coordinates.data() +
          static_cast<std::size_t>(cells[static_cast<std::size_t>(c) * (dim + 1) + v]) * dim;
      for (int k = 0; k < dim; ++k) vertices[v][k] = x[k];
    }
    return make_simplex<dim>(vertices);
  }
};

/// Stage 1: sends owned master cells to the ranks whose slave box they overlap.
template <int dim>
class MasterExchange {
 public:
  /// Full exchange over `comm` (master.comm or a duplicate of it). `slave_boxes` holds every
  /// rank's owned-slave-cell box (index = rank); an owned master cell goes to rank r when its
  /// box inflated by `margin` overlaps slave_boxes[r]. Collective.
  void exchange(const mesh::Mesh& master, MPI_Comm comm, std::span<const Box<dim>> slave_boxes,
                double margin);
  /// Re-sends the current coordinates of the same vertices to the same ranks (the master
  /// moved, its mesh and partition did not). Collective.
  void refresh(const mesh::Mesh& master);
  const ReceivedMaster<dim>& received() const { return received_; }
  /// Master cells this rank sent in the last full exchange (counting repeats per rank).
  std::int64_t n_sent_cells() const { return n_sent_cells_; }

 private:
  MPI_Comm comm_ = MPI_COMM_NULL;
  // send side: per destination, the local master vertices it gets (in message order)
  std::vector<int> send_ranks_;
  std::vector<int> send_offsets_;   ///< into send_vertices_, send_ranks_.size() + 1
  std::vector<int> send_vertices_;  ///< local master vertex indices
  // receive side: per source, where each incoming vertex goes in received_
  std::vector<int> recv_ranks_;
  std::vector<int> recv_offsets_;   ///< into recv_position_, recv_ranks_.size() + 1
  std::vector<int> recv_position_;  ///< received-vertex index of each incoming vertex
  std::int64_t n_sent_cells_ = 0;
  ReceivedMaster<dim> received_;
};

// ------------------------------------------------------------------------------------------
// Stage 2: local acceleration structure and pair list
// ------------------------------------------------------------------------------------------

/// A uniform grid of bins over a set of boxes. A box no larger than a bin on every axis (a
/// "small" box: nearly all of them in a mesh of even size) is stored once, in the bin of its
/// lower corner, and the small boxes are kept sorted by bin, so a query scans contiguous
/// memory: the boxes that can reach the query have their lower corner in the bins from
/// (query.lower − bin size) to query.upper, and a row of bins along x is one run of boxes.
/// A larger box is listed in every bin it overlaps and reported from the first bin of the
/// overlap of its bin range with the query's only. Queries need no scratch state, so they are
/// const and thread-safe.
template <int dim>
class BoxGrid {
 public:
  /// Bins `boxes` (empty boxes are left out). The bin size is 1.5 times the mean box extent
  /// per axis, enlarged when needed to keep at most about 2 bins per box. Linear time.
  void build(std::span<const Box<dim>> boxes);
  /// Calls visit(i) once for each box i that overlaps `query` (closed boxes).
  template <class Visit>
  void query(const Box<dim>& query, Visit&& visit) const;
  std::size_t n_bins() const { return small_offsets_.empty() ? 0 : small_offsets_.size() - 1; }
  std::size_t memory_bytes() const {
    return (small_boxes_.capacity() + large_boxes_.capacity()) * sizeof(Box<dim>) +
           (small_offsets_.capacity() + small_ids_.capacity() + large_offsets_.capacity() +
            large_entries_.capacity() + large_ids_.capacity()) *
               sizeof(int);
  }

 private:
  int bin_coordinate(double x, int axis) const {
    const double t = (x - origin_[axis]) * inverse_size_[axis];
    if (!(t > 0.0)) return 0;  // also NaN
    return t >= counts_[axis] ? counts_[axis] - 1 : static_cast<int>(t);
  }

  Point<dim> origin_{};
  Point<dim> inverse_size_{};
  Point<dim> bin_size_{};  ///< a small box's extent is at most this on every axis
  Point<dim> reach_{};     ///< bin_size_ plus round-off slack, for the small-box queries
  std::array<int, dim> counts_{};
  // small boxes, sorted by the bin of their lower corner
  std::vector<int> small_offsets_;  ///< per bin + 1, into small_boxes_ / small_ids_
  std::vector<Box<dim>> small_boxes_;
  std::vector<int> small_ids_;
  // large boxes, listed in every bin they overlap
  std::vector<int> large_offsets_;  ///< per bin + 1 (empty when there are no large boxes)
  std::vector<int> large_entries_;  ///< indices into large_boxes_ / large_ids_
  std::vector<Box<dim>> large_boxes_;
  std::vector<int> large_ids_;
};

/// Face neighbours of the cells of a simplicial mesh: entry c·(dim + 1) + i is the cell across
/// the face opposite vertex i of cell c, or −1 (boundary face, or a face shared by more than
/// two cells: left open). `cells`: n_cells × (dim + 1) vertex indices in [0, n_vertices).
/// Faces are bucketed by their smallest vertex (counting sort), then sorted within a bucket.
std::vector<int> face_neighbors(int dim, std::span<const int> cells, int n_vertices);

/// Options of the pair search.
struct SearchOptions {
  /// Master boxes are inflated by this much [m] in the exchange and in the grid, so the
  /// search stays valid while no master vertex moves farther (per coordinate) from where it
  /// was at the last full search. 0 for a fixed master.
  double margin = 0.0;
  /// Advancing front: prepare face neighbours and leave the pair list to sweep() (false:
  /// the grid pair list, made by the constructor and by update_master()).
  bool front = false;
};

/// What the last search (or update) did, on this rank.
struct SearchStatistics {
  bool full = true;                    ///< full search (false: pattern and grid reused)
  std::int64_t sent_master_cells = 0;  ///< owned master cells sent (repeats per rank counted)
  std::int64_t received_master_cells = 0;
  /// (owned slave cell, received master cell) with boxes overlapping (front: pairs tested)
  std::int64_t candidate_pairs = 0;
  std::int64_t pairs = 0;  ///< kept after the separating-plane filter (front: overlapping)
  std::int64_t front_fallbacks = 0;  ///< front: owned slave cells that also used the grid
  double exchange_seconds = 0;       ///< stage 1 (boxes, messages, merge) or coordinate refresh
  double grid_seconds = 0;           ///< master simplices and grid (front: and face neighbours)
  double query_seconds = 0;          ///< slave simplices, grid queries, filter (front: the sweep)
  std::size_t memory_bytes = 0;      ///< received data, simplices, grid and pairs
};

/// Stages 1 and 2: the pairs (owned slave cell, received master cell) to integrate.
template <int dim>
class PairSearch {
 public:
  /// Full search. Both meshes must be distributed over the same communicator (or both be
  /// whole serial meshes), have dimension dim, and outlive this object (the slave is read
  /// again by update_master). Collective.
  PairSearch(const mesh::Mesh& slave, const mesh::Mesh& master, const SearchOptions& options = {});
  PairSearch(const PairSearch&) = delete;
  PairSearch& operator=(const PairSearch&) = delete;
  ~PairSearch();

  /// The master's coordinates changed (owned and ghost vertices, same cells and partition):
  /// reuses the exchange pattern and the grid if every master vertex stayed within the margin
  /// of its position at the last full search, else searches again. Returns true when reused.
  /// Collective.
  bool update_master(const mesh::Mesh& master);

  const mesh::Mesh& slave() const { return *slave_; }
  const ReceivedMaster<dim>& master() const { return exchange_.received(); }
  /// Simplex of each received master cell (current coordinates).
  std::span<const Simplex<dim>> master_simplices() const { return master_simplices_; }
  /// The received master cells paired with owned slave cell c (front: those the last sweep
  /// found overlapping, in the order found).
  std::span<const int> pairs_of(int c) const {
    if (cell_pairs_.empty()) return {};
    const CellPairs& p = cell_pairs_[static_cast<std::size_t>(c)];
    return {pair_chunks_[static_cast<std::size_t>(p.chunk)].data() + p.start,
            static_cast<std::size_t>(p.count)};
  }
  /// Number of pairs (over all owned slave cells).
  std::int64_t n_pairs() const { return statistics_.pairs; }
  const SearchStatistics& statistics() const { return statistics_; }
  /// A duplicate of the meshes' communicator, private to this search.
  MPI_Comm comm() const { return comm_; }

  /// Advancing front over the owned slave cells (SearchOptions::front only), in order c = 0,
  /// 1, ...: test(c, s, m, crossed) → Contact is called at most once per (c, m) with s the
  /// simplex of slave cell c, then finish(c, s, overlapping) with the master cells it found
  /// overlapping (every owned cell, in order; also stored as pairs_of(c)). `crossed` comes in
  /// with all bits set; the test may clear bit i when no vertex of s lies strictly beyond face
  /// plane i of master cell m (λ_i ≥ −kPlaneTolerance: LocalIntegrals::crossed_faces_b).
  ///
  /// Per slave cell S: the seeds are the master cells that the first earlier face neighbour
  /// of S with any overlaps found; the front starts from one of them (the one whose box centre
  /// is nearest to the centroid of S, the likeliest to overlap S) and crosses the faces the
  /// test leaves in `crossed` of every master cell it does not call separated; only when it
  /// ends without an overlapping cell does it go on from the next seed not reached yet. Why
  /// that finds every overlapping cell: two points of int(S ∩ M) in master cells T₁, T₂ are
  /// joined by a segment in int S (S is convex) that, moved generically, crosses master cells
  /// through faces only, each of them overlapping S (the test never calls such a cell
  /// separated) and each face meeting int S; so from one overlapping cell the front reaches
  /// all of them unless the segment leaves the received master cells, through a face without
  /// a neighbour of a cell the front reached, which S must then cross. So S falls back to the
  /// grid (box candidates the front has not tested) when the front found no overlapping cell
  /// (no seed, disconnected pieces, S outside M) or when some crossed cell has an open face
  /// in `crossed` whose plane S crosses (a vertex of S at λ < −kPlaneTolerance): the master's
  /// boundary, a face to a cell this rank did not receive, a non-conforming face. The same
  /// argument lets the front skip the faces the segment cannot go through: those whose plane S
  /// does not cross, and those of an overlapping cell that S ∩ M_cell does not touch (the
  /// kernel's crossed_faces_b). A degenerate master cell has no interior for the segment to
  /// cross, but its faces may be the only link between two overlapping cells, so the front
  /// crosses all its faces.
  template <class Test, class Finish>
  void sweep(Test&& test, Finish&& finish);
  /// Frees the pair list and the front's scratch (pairs_of() is empty afterwards); for a
  /// caller that consumed the pairs in sweep()'s finish().
  void release_pairs() {
    cell_pairs_ = std::vector<CellPairs>();
    pair_chunks_ = std::vector<std::vector<int>>();
    visited_ = std::vector<int>();
    queue_ = std::vector<int>();
  }

 private:
  void full_search();
  void build_grid();
  void query_pairs();
  double master_displacement() const;  // local max |x − x_ref|_∞ over owned cells' vertices

  const mesh::Mesh* slave_;
  const mesh::Mesh* master_;
  SearchOptions options_;
  MPI_Comm comm_ = MPI_COMM_NULL;
  MasterExchange<dim> exchange_;
  std::vector<Simplex<dim>> master_simplices_;
  BoxGrid<dim> grid_;
  std::vector<double> reference_coordinates_;  ///< master local coordinates at the last full search
  // Pairs in chunks of about kChunk ints (a cell's pairs never straddle two chunks): no
  // doubling copy while the list grows, and the chunks are reused by the next search.
  static constexpr std::size_t kChunk = std::size_t{1} << 20;
  struct CellPairs {
    int chunk = 0, start = 0, count = 0;
  };
  std::vector<CellPairs> cell_pairs_;
  std::vector<std::vector<int>> pair_chunks_;
  std::vector<int> scratch_;  ///< one cell's pairs while it is searched
  SearchStatistics statistics_;
  // advancing front
  std::vector<int> slave_neighbors_;   ///< face_neighbors of the owned slave cells
  std::vector<int> master_neighbors_;  ///< face_neighbors of the received master cells
  std::vector<int> visited_;           ///< per received master cell: last slave cell testing it
  std::vector<int> queue_;             ///< the front of one slave cell
  /// The seed (a received master cell) whose box centre is nearest to the centroid of s.
  int nearest_seed(const Simplex<dim>& s, std::span<const int> seeds) const;
  void store_pairs(int c, std::size_t& chunk);
  void finish_statistics();
};

// ------------------------------------------------------------------------------------------

template <int dim>
template <class Visit>
void BoxGrid<dim>::query(const Box<dim>& query, Visit&& visit) const {
  if (small_offsets_.empty() || query.is_empty()) return;
  std::array<int, dim> lo, hi;
  // Small boxes: lower corner in [query.lower − bin size, query.upper]; rows along x are
  // contiguous runs of small_boxes_.
  for (int k = 0; k < dim; ++k) {
    lo[k] = bin_coordinate(query.lower[k] - reach_[k], k);
    hi[k] = bin_coordinate(query.upper[k], k);
  }
  std::array<int, dim> bin = lo;
  while (true) {
    int index = 0;
    for (int k = dim - 1; k >= 1; --k) index = index * counts_[k] + bin[k];
    index *= counts_[0];
    const int end = small_offsets_[index + hi[0] + 1];
    for (int e = small_offsets_[index + lo[0]]; e < end; ++e)
      if (small_boxes_[e].overlaps(query)) visit(small_ids_[e]);
    int k = 1;
    while (k < dim && bin[k] == hi[k]) {
      bin[k] = lo[k];
      ++k;
    }
    if (k == dim) break;
    ++bin[k];
  }
  if (large_offsets_.empty()) return;
  for (int k = 0; k < dim; ++k) {
    lo[k] = bin_coordinate(query.lower[k], k);
    hi[k] = bin_coordinate(query.upper[k], k);
  }
  bin = lo;
  while (true) {
    int index = 0;
    for (int k = dim - 1; k >= 0; --k) index = index * counts_[k] + bin[k];
    for (int e = large_offsets_[index]; e < large_offsets_[index + 1]; ++e) {
      const int i = large_entries_[e];
      const Box<dim>& box = large_boxes_[i];
      if (!box.overlaps(query)) continue;
      // report from the first bin of the overlap of the two bin ranges only
      bool first = true;
      for (int k = 0; k < dim && first; ++k)
        first = bin[k] == std::max(lo[k], bin_coordinate(box.lower[k], k));
      if (first) visit(large_ids_[i]);
    }
    int k = 0;
    while (k < dim && bin[k] == hi[k]) {
      bin[k] = lo[k];
      ++k;
    }
    if (k == dim) break;
    ++bin[k];
  }
}

template <int dim>
int PairSearch<dim>::nearest_seed(const Simplex<dim>& s, std::span<const int> seeds) const {
  Point<dim> centroid{};
  for (const Point<dim>& v : s.vertices)
    for (int d = 0; d < dim; ++d) centroid[d] += v[d] / (dim + 1);
  int nearest = seeds[0];
  double nearest_distance = std::numeric_limits<double>::infinity();
  for (const int m : seeds) {
    const Simplex<dim>& t = master_simplices_[static_cast<std::size_t>(m)];
    double distance = 0.0;  // squared, to twice the box centre
    for (int d = 0; d < dim; ++d) {
      const double e = t.box_lower[d] + t.box_upper[d] - 2.0 * centroid[d];
      distance += e * e;
    }
    if (distance < nearest_distance) {
      nearest_distance = distance;
      nearest = m;
    }
  }
  return nearest;
}

template <int dim>
template <class Test, class Finish>
void PairSearch<dim>::sweep(Test&& test, Finish&& finish) {
  COAPT_ASSERT(options_.front, "PairSearch::sweep needs SearchOptions::front");
  const auto start = std::chrono::steady_clock::now();
  constexpr int k = dim + 1;
  const mesh::Mesh& slave = *slave_;
  cell_pairs_.assign(static_cast<std::size_t>(slave.n_owned_cells), CellPairs{});
  for (auto& chunk : pair_chunks_) chunk.clear();  // keeps the capacity
  std::size_t chunk = 0;
  if (pair_chunks_.empty()) pair_chunks_.emplace_back();
  visited_.assign(master_simplices_.size(), -1);
  std::int64_t tests = 0, fallbacks = 0;
  for (int c = 0; c < slave.n_owned_cells; ++c) {
    const Simplex<dim> s = cell_simplex<dim>(slave, c);
    scratch_.clear();
    if (!s.degenerate()) {
      queue_.clear();
      std::span<const int> seeds;
      for (int i = 0; i < k; ++i) {
        const int n = slave_neighbors_[static_cast<std::size_t>(c) * k + i];
        if (n < 0 || n > c || cell_pairs_[static_cast<std::size_t>(n)].count == 0) continue;
        seeds = pairs_of(n);
        break;
      }
      // One seed at a time (see above): the nearest first, then the others in order.
      int nearest = seeds.empty() ? -1 : nearest_seed(s, seeds);
      std::size_t next_seed = 0;
      bool open = false;  // a crossed cell has an open face whose plane S crosses
      for (std::size_t q = 0;; ++q) {
        if (q == queue_.size()) {        // the front from the seeds so far has ended
          if (!scratch_.empty()) break;  // ... and found all the cells S overlaps
          int seed = -1;
          if (nearest >= 0) {
            seed = nearest;
            nearest = -1;
          } else {
            while (next_seed < seeds.size() && visited_[seeds[next_seed]] == c) ++next_seed;
            if (next_seed < seeds.size()) seed = seeds[next_seed++];
          }
          if (seed < 0) break;
          visited_[seed] = c;
          queue_.push_back(seed);
        }
        const int m = queue_[q];
        ++tests;
        unsigned crossed = ~0u;
        const Contact contact = test(c, s, m, crossed);
        if (contact == Contact::separated) {
          // A degenerate (flat) master cell is "separated" from everything but may sit between
          // two cells that overlap S: the front walks through it.
          if (!master_simplices_[m].degenerate()) continue;
          crossed = ~0u;
        }
        if (contact == Contact::overlapping) scratch_.push_back(m);
        const int* across = master_neighbors_.data() + static_cast<std::size_t>(m) * k;
        for (int i = 0; i < k; ++i) {
          if (!((crossed >> i) & 1u)) continue;  // S does not cross this face's plane
          const int n = across[i];
          if (n >= 0) {
            if (visited_[n] != c) {
              visited_[n] = c;
              queue_.push_back(n);
              // The kernel first reads the measure and the box, at the end of the simplex:
              // fetch that line now, so the load that used to miss is in cache when n is
              // tested (was ~3 % of the sweep in CPU samples).
              __builtin_prefetch(&master_simplices_[n].measure);
            }
          } else if (!open) {
            const Simplex<dim>& t = master_simplices_[m];
            for (int v = 0; v < k && !open; ++v)
              open = t.barycentric(i, s.vertices[v]) < -kPlaneTolerance;
          }
        }
      }
      if (scratch_.empty() || open) {
        ++fallbacks;
        grid_.query(Box<dim>::of(s), [&](int m) {
          if (visited_[m] == c) return;
          visited_[m] = c;
          ++tests;
          unsigned crossed = ~0u;
          if (test(c, s, m, crossed) == Contact::overlapping) scratch_.push_back(m);
        });
      }
    }
    store_pairs(c, chunk);
    finish(c, s, pairs_of(c));
  }
  pair_chunks_.resize(chunk + 1);
  std::int64_t n_pairs = 0;
  for (const CellPairs& p : cell_pairs_) n_pairs += p.count;
  statistics_.candidate_pairs = tests;
  statistics_.pairs = n_pairs;
  statistics_.front_fallbacks = fallbacks;
  finish_statistics();
  statistics_.query_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace coapt::transfer
