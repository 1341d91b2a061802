#include "hystlab/models/preisach_operator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "hystlab/models/everett_table.hpp"

namespace hystlab::models {
namespace {

// One turning point on the memory stack and the term it adds to the output while it is there:
// an M at an odd position adds +F(M, m before it), an m at an even position adds -F(M before it, m)
// (the closed pairs of Eq. 7; the m at position 0 is δmin and adds nothing).
struct StackEntry {
  double value = 0.0;
  std::uint32_t start = 0;
  InterpolationStencil stencil{};
  double sign = 0.0;
};

}  // namespace

PreisachOperator::PreisachOperator(const Grid& grid, std::span<const double> input) : grid_(grid) {
  if (input.size() >= std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("fit: " + std::to_string(input.size()) + " samples are more than one record may hold");
  const EverettTable shape(grid);
  std::vector<StackEntry> stack{StackEntry{grid.lo, 0, {}, 0.0}};
  auto close = [&](const StackEntry& e, std::uint32_t end) {
    if (e.start == end) return;  // pushed and wiped out by the same sample
    for (int t = 0; t < e.stencil.size; ++t)
      if (e.stencil.weight[static_cast<std::size_t>(t)] != 0.0)
        held_.push_back(HeldTerm{static_cast<std::uint32_t>(e.stencil.node[static_cast<std::size_t>(t)]), e.start, end,
                                 e.sign * e.stencil.weight[static_cast<std::size_t>(t)]});
  };
  auto push = [&](double v, std::uint32_t k) {
    const double below = stack.back().value;
    const bool is_max = (stack.size() & 1U) != 0U;
    stack.push_back(StackEntry{v, k, is_max ? shape.stencil(v, below) : shape.stencil(below, v), is_max ? 1.0 : -1.0});
  };
  auto pop = [&](std::uint32_t k) {
    close(stack.back(), k);
    stack.pop_back();
  };
  live_.resize(input.size());
  double x_prev = grid.lo;
  for (std::size_t s = 0; s < input.size(); ++s) {
    const auto k = static_cast<std::uint32_t>(s);
    if (!std::isfinite(input[s])) throw std::invalid_argument("fit: sample " + std::to_string(s) + " is not a finite number");
    const double x = std::clamp(input[s], grid.lo, grid.hi);
    if (x != x_prev) {  // the same memory rules as PreisachModel and preisach_regressors
      const bool up = x > x_prev;
      if (up != ((stack.size() & 1U) != 0U)) push(x_prev, k);
      if (up) {
        while (stack.size() >= 3 && x >= stack[stack.size() - 2].value) {
          pop(k);
          pop(k);
        }
      } else {
        while (stack.size() >= 2 && x <= stack[stack.size() - 2].value) {
          if (stack.size() == 2) {
            pop(k);
            break;
          }
          pop(k);
          pop(k);
        }
      }
      x_prev = x;
    }
    const bool rising = (stack.size() & 1U) != 0U;
    const InterpolationStencil st = rising ? shape.stencil(x, stack.back().value) : shape.stencil(stack.back().value, x);
    LiveStencil& l = live_[s];
    for (std::size_t t = 0; t < 4; ++t) {
      const bool used = static_cast<int>(t) < st.size;
      l.node[t] = used ? static_cast<std::uint32_t>(st.node[t]) : 0U;
      l.weight[t] = used ? (rising ? st.weight[t] : -st.weight[t]) : 0.0;
    }
  }
  const auto end = static_cast<std::uint32_t>(input.size());
  while (stack.size() > 1) pop(end);
  held_.shrink_to_fit();
}

std::size_t PreisachOperator::memory_bytes() const noexcept { return held_.capacity() * sizeof(HeldTerm) + live_.capacity() * sizeof(LiveStencil); }

void PreisachOperator::apply(std::span<const double> v, std::span<double> out) const {
  if (v.size() != nodes() || out.size() != samples()) throw std::invalid_argument("PreisachOperator::apply: sizes");
  // Held terms through a difference array kept in `out` itself (no allocation per call): +c at
  // a term's first sample, -c after its last; a term alive to the end needs no closing entry.
  std::fill(out.begin(), out.end(), 0.0);
  for (const HeldTerm& t : held_) {
    const double c = t.weight * v[t.node];
    out[t.start] += c;
    if (t.end < out.size()) out[t.end] -= c;
  }
  double held = 0.0;
  for (std::size_t k = 0; k < samples(); ++k) {
    held += out[k];
    const LiveStencil& l = live_[k];
    out[k] = held + l.weight[0] * v[l.node[0]] + l.weight[1] * v[l.node[1]] + l.weight[2] * v[l.node[2]] + l.weight[3] * v[l.node[3]];
  }
}

void PreisachOperator::apply_transpose(std::span<const double> u, std::span<double> g) const {
  std::vector<double> prefix;
  apply_transpose(u, g, prefix);
}

void PreisachOperator::apply_transpose(std::span<const double> u, std::span<double> g, std::vector<double>& prefix) const {
  if (u.size() != samples() || g.size() != nodes()) throw std::invalid_argument("PreisachOperator::apply_transpose: sizes");
  // prefix[k] = Σ_{j<k} u[j], so a held term's share is weight * (prefix[end] - prefix[start]).
  prefix.resize(samples() + 1);
  prefix[0] = 0.0;
  for (std::size_t k = 0; k < samples(); ++k) prefix[k + 1] = prefix[k] + u[k];
  std::fill(g.begin(), g.end(), 0.0);
  for (const HeldTerm& t : held_) g[t.node] += t.weight * (prefix[t.end] - prefix[t.start]);
  for (std::size_t k = 0; k < samples(); ++k) {
    const LiveStencil& l = live_[k];
    for (std::size_t t = 0; t < 4; ++t) g[l.node[t]] += l.weight[t] * u[k];
  }
}

}  // namespace hystlab::models
