#include "hystlab/models/preisach_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace hystlab::models {

PreisachModel::PreisachModel(std::shared_ptr<const EverettTable> table, PreisachOptions options) : table_(std::move(table)), options_(options) {
  if (!table_) throw std::invalid_argument("preisach: no table");
  if (options_.max_turning_points < 3) throw std::invalid_argument("preisach: max_turning_points must be >= 3");
  if (!(options_.merge_tolerance >= 0.0)) throw std::invalid_argument("preisach: merge_tolerance must be >= 0");
  turning_.assign(options_.max_turning_points + 1, 0.0);     // + 1 spare slot
  closed_.assign(options_.max_turning_points / 2 + 2, 0.0);  // + 1 scratch slot
  replay_.assign(options_.max_turning_points + 1, 0.0);
  reset();
}

void PreisachModel::replace_table(std::shared_ptr<const EverettTable> table) {
  if (!table || !table->grid().same_nodes(table_->grid())) throw std::invalid_argument("preisach: the new table is not on the nodes of the model's table");
  replace_table_on_same_nodes(std::move(table));
}

void PreisachModel::replace_table_on_same_nodes(std::shared_ptr<const EverettTable> table) noexcept {
  const std::size_t len = now_.len;
  const double x = now_.x;
  const std::uint64_t saturations = saturations_, merges = merges_, invalid = invalid_;
  std::copy(turning_.begin(), turning_.begin() + static_cast<std::ptrdiff_t>(len), replay_.begin());
  table_ = std::move(table);
  // The stored turning points alternate and nest (what the wiping-out rule left), so driving
  // them again stores the same ones, and the sums of the closed pairs with the new table's values.
  reset();
  for (std::size_t k = 1; k < len; ++k) (void)step(replay_[k]);
  (void)step(x);
  saturations_ = saturations, merges_ = merges, invalid_ = invalid;
}

void PreisachModel::reset() noexcept {
  now_ = Now{1, table_->grid().lo, 0.0, 0.0, wipe_bound(turning_.data(), 1), BranchCell{}};
  turning_[0] = table_->grid().lo;
  closed_[0] = 0.0;
  saturations_ = merges_ = invalid_ = 0;
}

}  // namespace hystlab::models

namespace hystlab::models {
namespace {
constexpr double kPreisachStateKind = 1.0;
constexpr std::size_t kPreisachHead = 8;  // kind, len, x, f, base and the three counters

// A count stored as a double: a whole number in [lo, hi], or the error names it.
std::size_t state_count(double v, double lo, double hi, const char* what) {
  if (!(v >= lo && v <= hi) || v != std::floor(v))
    throw std::invalid_argument(std::string("model state: ") + what + " is not a whole number in [" + std::to_string(static_cast<long long>(lo)) + ", " +
                                std::to_string(static_cast<long long>(hi)) + "]");
  return static_cast<std::size_t>(v);
}
}  // namespace

std::vector<double> PreisachModel::save_state() const {
  std::vector<double> s{kPreisachStateKind,           static_cast<double>(now_.len), now_.x, now_.f, now_.base, static_cast<double>(saturations_),
                        static_cast<double>(merges_), static_cast<double>(invalid_)};
  s.insert(s.end(), turning_.begin(), turning_.begin() + static_cast<std::ptrdiff_t>(now_.len));
  s.insert(s.end(), closed_.begin(), closed_.begin() + static_cast<std::ptrdiff_t>(now_.len / 2 + 1));
  // Falling (len even), the last one, closed[len/2], is a scratch slot nothing reads before the
  // next reversal writes it; its value depends on the model's earlier history. Saved as 0, so
  // that two models in the same memory save the same numbers (the kept-cell test compares them
  // whole after a restore).
  if (now_.len % 2 == 0) s.back() = 0.0;
  return s;
}

// Every number is checked before any is taken, so a refused state leaves the model as it was.
void PreisachModel::restore_state(std::span<const double> s) {
  if (s.size() < kPreisachHead || s[0] != kPreisachStateKind) throw std::invalid_argument("model state: not the state of a Preisach (table) model");
  const std::size_t len = state_count(s[1], 1, static_cast<double>(options_.max_turning_points), "the number of turning points");
  if (s.size() != kPreisachHead + len + len / 2 + 1)
    throw std::invalid_argument("model state: " + std::to_string(s.size()) + " numbers where " + std::to_string(len) + " turning points need " +
                                std::to_string(kPreisachHead + len + len / 2 + 1));
  constexpr double kMaxCount = 9007199254740992.0;  // 2^53: counts up to it are exact in a double
  for (std::size_t k = 5; k < 8; ++k) (void)state_count(s[k], 0, kMaxCount, "a counter");
  for (std::size_t k = 2; k < s.size(); ++k)
    if (!std::isfinite(s[k])) throw std::invalid_argument("model state: value " + std::to_string(k) + " is not a finite number");
  const Grid& g = table_->grid();
  const std::span<const double> turning = s.subspan(kPreisachHead, len);
  if (turning[0] != g.lo) throw std::invalid_argument("model state: the first turning point is not the table's lower end (another table's state?)");
  for (const double t : turning)
    if (t < g.lo || t > g.hi) throw std::invalid_argument("model state: a turning point lies outside the table's range (another table's state?)");
  if (s[2] < g.lo || s[2] > g.hi) throw std::invalid_argument("model state: the input lies outside the table's range (another table's state?)");
  now_ = Now{len, s[2], s[3], s[4], wipe_bound(turning.data(), len), BranchCell{}};  // the cell is read again at the next step
  saturations_ = static_cast<std::uint64_t>(s[5]);
  merges_ = static_cast<std::uint64_t>(s[6]);
  invalid_ = static_cast<std::uint64_t>(s[7]);
  std::copy(turning.begin(), turning.end(), turning_.begin());
  const std::span<const double> closed = s.subspan(kPreisachHead + len);
  std::copy(closed.begin(), closed.end(), closed_.begin());
}

}  // namespace hystlab::models
