#include "fit_gram.hpp"

#include "fit_system.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <vector>

namespace hystlab::models::fit {
namespace {

using Term = PreisachOperator::HeldTerm;
using Triplet = Eigen::Triplet<double, std::int32_t>;
using Sparse = Eigen::SparseMatrix<double, Eigen::RowMajor, std::int32_t>;

// Contributions gathered as triplets and summed into the matrix a chunk at a time, so the
// transient memory is one chunk whatever the record's length.
class Accumulator {
 public:
  Accumulator(std::size_t dim, std::size_t max_nonzeros) : g_(static_cast<Eigen::Index>(dim), static_cast<Eigen::Index>(dim)), max_(max_nonzeros) {
    buf_.reserve(kChunk);
  }
  // G += v (e_a e_bᵀ + e_b e_aᵀ): a pair of distinct terms of one row (on the diagonal twice
  // when both are the same node). Only the lower triangle is kept.
  void add(std::uint32_t a, std::uint32_t b, double v) {
    if (a == b) return add_diagonal(a, 2.0 * v);
    if (v == 0.0 || over_) return;
    buf_.emplace_back(static_cast<std::int32_t>(std::max(a, b)), static_cast<std::int32_t>(std::min(a, b)), v);
    if (buf_.size() >= kChunk) flush();
  }
  // G(a, a) += v: a term with itself.
  void add_diagonal(std::uint32_t a, double v) {
    if (v == 0.0 || over_) return;
    buf_.emplace_back(static_cast<std::int32_t>(a), static_cast<std::int32_t>(a), v);
    if (buf_.size() >= kChunk) flush();
  }
  void flush() {
    if (buf_.empty() || over_) return;
    Sparse chunk(g_.rows(), g_.cols());
    chunk.setFromTriplets(buf_.begin(), buf_.end());
    buf_.clear();
    if (g_.nonZeros() == 0) {
      g_ = std::move(chunk);
    } else {
      Sparse sum = g_ + chunk;
      g_ = std::move(sum);
    }
    over_ = static_cast<std::size_t>(g_.nonZeros()) > max_;
    if (over_) g_ = Sparse(g_.rows(), g_.cols());
  }
  [[nodiscard]] bool over() const noexcept { return over_; }
  Sparse take() { return std::move(g_); }

 private:
  static constexpr std::size_t kChunk = std::size_t{1} << 21;  // 32 MiB of triplets
  Sparse g_;
  std::size_t max_;
  std::vector<Triplet> buf_;
  bool over_ = false;
};

// The held terms and the offset (a term alive over the whole record), by start, the longest first
// among those starting together: then every term's enclosing terms come before it.
std::vector<Term> sorted_terms(const PreisachOperator& op) {
  std::vector<Term> t(op.held().begin(), op.held().end());
  t.push_back(Term{static_cast<std::uint32_t>(op.nodes()), 0, static_cast<std::uint32_t>(op.samples()), 1.0});
  std::sort(t.begin(), t.end(), [](const Term& a, const Term& b) { return a.start != b.start ? a.start < b.start : a.end > b.end; });
  return t;
}

// held × held: each term with itself and with every term enclosing it, over its training samples.
void held_pairs(std::span<const Term> terms, std::span<const double> count, Accumulator& acc) {
  std::vector<const Term*> chain;  // enclosing terms, the innermost last
  for (const Term& t : terms) {
    while (!chain.empty() && chain.back()->end <= t.start) chain.pop_back();
    const double n = count[t.end] - count[t.start];
    if (n > 0.0) {
      acc.add_diagonal(t.node, t.weight * t.weight * n);
      for (const Term* outer : chain) acc.add(outer->node, t.node, outer->weight * t.weight * n);
    }
    chain.push_back(&t);
  }
}

// One run of samples with the same stencil nodes and the same terms alive: the stencil's weights
// summed over it (first and second moments, training samples only).
struct Run {
  std::array<std::uint32_t, 4> node{};
  std::array<double, 4> sum{};
  std::array<double, 16> cross{};
  bool open = false;
};

void close_run(Run& r, std::span<const Term* const> alive, Accumulator& acc) {
  if (!r.open) return;
  for (const Term* h : alive)
    for (std::size_t a = 0; a < 4; ++a) acc.add(h->node, r.node[a], h->weight * r.sum[a]);
  for (std::size_t a = 0; a < 4; ++a) {
    acc.add_diagonal(r.node[a], r.cross[a * 4 + a]);
    for (std::size_t b = a + 1; b < 4; ++b) acc.add(r.node[a], r.node[b], r.cross[a * 4 + b]);
  }
  r = Run{};
}

// held × live and live × live, one pass over the samples with the alive terms kept as a chain.
void live_pairs(const PreisachOperator& op, std::span<const Term> terms, std::span<const double> mask, Accumulator& acc) {
  const auto live = op.live();
  std::vector<const Term*> chain;
  std::size_t next = 0;
  Run run;
  for (std::size_t k = 0; k < live.size() && !acc.over(); ++k) {
    bool changed = false;
    while (!chain.empty() && chain.back()->end <= k) {
      if (!changed) close_run(run, chain, acc);
      changed = true;
      chain.pop_back();
    }
    while (next < terms.size() && terms[next].start == k) {
      if (!changed) close_run(run, chain, acc);
      changed = true;
      if (terms[next].end > terms[next].start) chain.push_back(&terms[next]);
      ++next;
    }
    const auto& s = live[k];
    if (run.open && s.node != run.node) close_run(run, chain, acc);
    if (mask[k] == 0.0) continue;
    run.open = true;
    run.node = s.node;
    for (std::size_t a = 0; a < 4; ++a) {
      const double wa = mask[k] * s.weight[a];
      run.sum[a] += wa;
      for (std::size_t b = a; b < 4; ++b) run.cross[a * 4 + b] += wa * s.weight[b];
    }
  }
  close_run(run, chain, acc);
}

}  // namespace

std::size_t gram_limit(const PreisachOperator& op) noexcept { return op.held_terms() + 4 * op.samples(); }

NodeGram::NodeGram(const PreisachOperator& op, std::span<const double> mask, std::size_t max_nonzeros) {
  if (mask.size() != op.samples()) throw std::invalid_argument("fit: the mask must have one value per sample");
  std::vector<double> count(op.samples() + 1, 0.0);  // training samples before k
  for (std::size_t k = 0; k < op.samples(); ++k) count[k + 1] = count[k] + mask[k];
  const std::vector<Term> terms = sorted_terms(op);
  Accumulator acc(op.nodes() + 1, max_nonzeros);
  held_pairs(terms, count, acc);
  live_pairs(op, terms, mask, acc);
  acc.flush();
  formed_ = !acc.over();
  g_ = acc.take();
  g_.makeCompressed();
}

std::vector<double> NodeGram::cell_diagonal(const Grid& grid) const {
  const std::size_t nodes = grid.node_count();
  std::vector<int> row_of(nodes), col_of(nodes);
  for (int i = 0; i <= grid.n; ++i)
    for (int j = 0; j <= i; ++j) {
      row_of[Grid::index(i, j)] = i;
      col_of[Grid::index(i, j)] = j;
    }
  std::vector<double> at(nodes, 0.0), cells(grid.cell_count(), 0.0);
  for (Index a = 0; a < static_cast<Index>(nodes); ++a)
    for (Sparse::InnerIterator e(g_, a); e; ++e) {
      const auto b = static_cast<std::size_t>(e.col());
      if (b >= nodes) continue;  // the offset
      const int i = std::min(row_of[static_cast<std::size_t>(a)], row_of[b]), j = std::max(col_of[static_cast<std::size_t>(a)], col_of[b]);
      if (j < i) at[Grid::index(i, j)] += (b == static_cast<std::size_t>(a) ? 1.0 : 2.0) * e.value();
    }
  nodes_to_cells_transpose(grid, at, cells);
  return cells;
}

void NodeGram::apply(std::span<const double> v, std::span<double> out) const {
  if (v.size() != size() || out.size() != size()) throw std::invalid_argument("NodeGram::apply: sizes");
  // The lower triangle read once: each entry below the diagonal serves its row and its column.
  std::fill(out.begin(), out.end(), 0.0);
  const Index* start = g_.outerIndexPtr();
  const Index* col = g_.innerIndexPtr();
  const double* val = g_.valuePtr();
  for (std::size_t r = 0; r < v.size(); ++r) {
    const double xr = v[r];
    double acc = 0.0;
    for (auto e = static_cast<std::size_t>(start[r]); e < static_cast<std::size_t>(start[r + 1]); ++e) {
      const auto c = static_cast<std::size_t>(col[e]);
      if (c == r) {
        acc += val[e] * xr;
      } else {
        acc += val[e] * v[c];
        out[c] += val[e] * xr;
      }
    }
    out[r] += acc;
  }
}

NodeGram NodeGram::minus(const NodeGram& part) const {
  if (part.size() != size()) throw std::invalid_argument("NodeGram::minus: sizes");
  NodeGram d;
  d.formed_ = formed_ && part.formed_;
  if (d.formed_) d.g_ = g_ - part.g_;
  d.g_.makeCompressed();
  return d;
}

}  // namespace hystlab::models::fit
