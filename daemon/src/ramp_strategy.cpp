// fot and waveform campaigns on a load frame: a list of ramps (the sequencer), each supervised
// for its arrival, and for fot the online table fitted as each descent passes the grid.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "acquisition_loop.hpp"
#include "adaptive_rows.hpp"
#include "hystlab/daemon/online_fot.hpp"
#include "hystlab/daemon/sequencer.hpp"
#include "hystlab/daemon/shakedown.hpp"
#include "hystlab/models/loop_figures.hpp"
#include "hystlab/models/online_table_builder.hpp"
#include "run_finish.hpp"

namespace hystlab::daemon {
namespace {

class RampStrategy final : public Strategy {
 public:
  explicit RampStrategy(Loop& L)
      : plan_(L.plan),
        seq_(schedule(L.plan), L.ctx.supervisor.settings().in_position_mm),
        settings_(L.ctx.supervisor.settings()),
        time_scale_(L.ctx.time_scale),
        shakedown_(L.plan.training) {
    series_ = L.job.prior_series;
    rows_begin_ = series_.size();
    halvings_seen_ = series_.halvings();
    if (plan_.kind != domain::CampaignKind::fot) return;
    const models::Grid g = domain::node_grid(plan_);
    if (plan_.design.adaptive) adaptive_.emplace(plan_);
    builder_ = std::make_shared<models::OnlineTableBuilder>(g);
    for (const models::FotNode& n : L.job.prior_nodes) (void)builder_->add(n);
    if (!L.job.prior_nodes.empty()) resume_rows_only(L);
    if (adaptive_ && !L.job.prior_nodes.empty()) design_done_at_start_ = adaptive_->stopped_before(*builder_);
    validation_to_rerun_ = !L.job.prior_nodes.empty();
    // The reversal dead band: the plan grid's, and for an adaptive design below a tenth of its
    // finest step (a reversal inside a fine cell must not pass one of its nodes).
    const double band = std::min({0.05 * domain::fot_grid(plan_).step(), 0.02, 0.1 * g.step()});
    fot_ = std::make_unique<OnlineFot>(g, band, [this, &L](const models::FotNode& n, double t) {
      if (builder_->add(n)) return;
      ++L.result.nodes;
      const auto run = L.result.run_id;
      L.ctx.writer.post([run, n, t](db::Store& s) { s.add_fot_node(run, n.alpha, n.beta, n.force_alpha, n.force_alpha_beta, t); });
    });
  }

  // Rows left to measure, or the validation input to run again: a campaign interrupted during its
  // validation run (or while finishing) resumes with every node measured, and its tables are scored
  // on a validation run of its own, driven whole now (the interrupted one's samples end where the
  // daemon stopped: a held-out score on part of the input would say less than it seems to).
  // An adaptive campaign resumed has work unless its design had stopped (its rows measured, the
  // next row past the budget or the gain, judged without the noise: more work, never less).
  [[nodiscard]] bool has_work() const override {
    if (adaptive_) return !design_done_at_start_ || (plan_.validation.enabled && validation_to_rerun_);
    return !(builder_ && builder_->complete()) || (builder_ && plan_.validation.enabled && validation_to_rerun_);
  }

  [[nodiscard]] CampaignPhase phase() const override {
    const Segment* cur = seq_.current();
    if (!cur) return CampaignPhase::ramping;
    if (cur->kind == SegmentKind::preamble) return CampaignPhase::preamble;
    if (cur->kind == SegmentKind::training) return CampaignPhase::training;
    if (cur->kind == SegmentKind::validation || validating_) return CampaignPhase::validation;
    if (rounds_ > 0) return CampaignPhase::retake;
    return seq_.in_position() ? CampaignPhase::dwelling : CampaignPhase::ramping;
  }

  bool on_frame(Loop& L, const drivers::RigSample& s) override {
    (validating_ ? validation_ : series_).add(s.displacement_mm, s.force_N);
    if (series_.halvings() != halvings_seen_) {  // the series was thinned 2:1: its indices follow
      halvings_seen_ = series_.halvings();
      rows_begin_ = (rows_begin_ + 1) / 2;
      cycle_start_.reset();  // a training cycle in progress is not judged on a thinned record
    }
    const std::size_t before = seq_.index();
    std::optional<SetpointCommand> cmd = seq_.step(s.time_s, s.displacement_mm);
    if (cmd) cmd = segment_changed(L, s, before, *cmd);
    if (cmd) {
      if (auto ec = L.ctx.rig.command(cmd->target_mm, cmd->rate_mm_s)) return L.command_failed(s.time_s, ec, "command");
      L.command_taken();
      arm_deadline(s.time_s, s.displacement_mm, *cmd);
      stalled_at_arm_ = L.stalled;
    } else if (seq_.index() == before && !seq_.done() && !seq_.in_position() && s.time_s > deadline_ + (L.stalled - stalled_at_arm_)) {
      // Arrival is what the deadline supervises: once in position, the dwell runs its course
      // (a browser-test campaign reached 0.000 mm late after a host stall, then "missed" it while dwelling).
      return target_missed(L, s);
    }
    if (fot_ && !validating_) {
      fot_->set_spacing(L.spacing);
      fot_->feed(s.time_s, s.displacement_mm, s.force_N, collecting());
      if (fot_->take_descent_completed()) evaluate(L);
      if (seq_.done() && !validating_) retake_rows(L);
      if (seq_.done() && !validating_) next_design_row(L, s);
    }
    return true;
  }

  void on_resume(Loop& L, double t, bool after_link_loss) override {
    const Segment* cur = seq_.current();
    if (!after_link_loss && plan_.kind == domain::CampaignKind::fot && cur && t - L.pause_started > L.ctx.resume_preamble_after_s) {
      // Memory-aware resume: the specimen drifted while held; wipe its memory at δmin and
      // re-take the row that was in progress.
      const std::size_t k = cur->kind == SegmentKind::descent ? seq_.index() - 1 : seq_.index();
      seq_.restart_at(k);
      seq_.insert_before_current({{plan_.lo_mm, plan_.ramp_rate_mm_s, plan_.dwell_s, SegmentKind::preamble, 0}});
      L.state(domain::CampaignState::running, "resumed after a long pause: wipe-out preamble to δmin, row re-taken");
    } else {
      seq_.restart_at(seq_.index());  // re-issue the current segment's command
      L.state(domain::CampaignState::running, after_link_loss ? "link back: segment taken again" : "resumed");
    }
    deadline_ = 1e300;
  }

  [[nodiscard]] bool done() const override { return seq_.done(); }

  void fill_finish(Loop& L, FinishJob& fj) override {
    if (validating_) L.result.run_id = campaign_run_;  // the tables and the quality record belong to the campaign's run
    fj.rows_begin = rows_begin_;
    fj.validation = std::move(validation_);
    if (shakedown_.cycles() > 0) fj.training_summary = shakedown_.summary();
    if (fot_) {
      fot_->finish();  // the last descent ends here: evaluate it like the others
      if (fot_->take_descent_completed()) evaluate(L);
    }
    fj.series = std::move(series_);
    if (builder_) fj.builder = adaptive_ ? table_builder() : std::move(builder_);
  }

 private:
  static std::vector<Segment> schedule(const domain::Plan& p) { return p.kind == domain::CampaignKind::fot ? fot_schedule(p) : waveform_schedule(p); }

  // A resumed campaign drives only the rows not yet complete (no training), then the validation.
  void resume_rows_only(Loop& L) {
    const std::vector<Segment> all = schedule(L.plan);
    std::vector<Segment> rest{all.front()};
    for (const Segment& seg : all) {
      if (seg.kind == SegmentKind::validation) rest.push_back(seg);
      if (seg.kind != SegmentKind::rise && seg.kind != SegmentKind::descent) continue;
      bool row_done = true;
      for (int j = 0; j < seg.row; ++j) row_done = row_done && builder_->identified(seg.row, j);
      if (!row_done) rest.push_back(seg);
    }
    seq_ = Sequencer(rest, settings_.in_position_mm);
  }

  // A new segment starts (cmd is its command). A training cycle ends: its figures go to the
  // shakedown rule, which may end training early (the rows start now). The validation input
  // starts: rows with a hole are taken again first, then the samples go to the validation run.
  // Returns the command to give (another segment's, when the schedule changed).
  std::optional<SetpointCommand> segment_changed(Loop& L, const drivers::RigSample& s, std::size_t before, SetpointCommand cmd) {
    const Segment* cur = seq_.current();
    if (before < seq_.size() && seq_.at(before).kind == SegmentKind::training && seq_.at(before).target_mm == plan_.lo_mm && cycle_start_ &&
        end_training_cycle(L)) {
      seq_.restart_at(seq_.find(SegmentKind::rise, seq_.index()));
      return seq_.step(s.time_s, s.displacement_mm);
    }
    if (cur && cur->kind == SegmentKind::training && cur->target_mm == plan_.hi_mm) cycle_start_ = series_.size() - 1;
    if (cur && cur->kind != SegmentKind::training && before < seq_.size() && seq_.at(before).kind == SegmentKind::training) rows_begin_ = series_.size() - 1;
    if (cur && cur->kind == SegmentKind::validation && !validating_) {
      const std::size_t at = seq_.index();
      if (builder_) retake_rows(L);
      if (seq_.index() != at || seq_.current() != cur || seq_.current()->kind != SegmentKind::validation)
        return seq_.step(s.time_s, s.displacement_mm);  // a retake was inserted before the validation
      if (next_design_row(L, s)) return seq_.step(s.time_s, s.displacement_mm);
      start_validation(L, s);
    }
    return cmd;
  }

  // The figures of the training cycle that just ended; true when training ends with it.
  bool end_training_cycle(Loop& L) {
    // The cycle's samples, copied into a buffer kept across cycles: O(cycle), no allocation once
    // it has grown to a cycle's length.
    const std::size_t b = *cycle_start_, e = series_.size() - 1;
    cycle_start_.reset();
    series_.copy(b, e + 1, cycle_);
    const std::span<const double> x(cycle_.x), f(cycle_.f);
    const auto top = static_cast<std::size_t>(std::max_element(x.begin(), x.end()) - x.begin());
    if (!(0 < top && top < e - b)) return false;
    const models::LoopFigures fig = models::loop_figures(x, f, 0, top, e - b);
    const ShakedownStep st = shakedown_.add(fig.peak_force_N, fig.energy_Nmm);
    domain::ShakedownEvent ev;
    ev.cycle = st.cycle, ev.consecutive = st.consecutive, ev.stable = st.stable;
    ev.peak_force_N = st.peak_force_N, ev.energy_Nmm = st.energy_Nmm, ev.damping_ratio = fig.damping_ratio,
    ev.secant_stiffness_N_mm = fig.secant_stiffness_N_mm;
    ev.peak_change_pct = st.peak_change_pct, ev.energy_change_pct = st.energy_change_pct;
    L.event(ev);
    if (!st.last) return false;
    L.event(domain::TrainingEvent{st.cycle, st.stable, plan_.training.until, shakedown_.summary()});
    rows_begin_ = e;
    return st.cycle < plan_.training.max_cycles;  // cycles left to skip
  }

  void start_validation(Loop& L, const drivers::RigSample& s) {
    if (fot_) {  // the rows are over with this sample: the last descent ends here (the validation input is no FOT row)
      fot_->set_spacing(L.spacing);
      fot_->feed(s.time_s, s.displacement_mm, s.force_N, false);
      fot_->finish();
      if (fot_->take_descent_completed()) evaluate(L);
    }
    validating_ = true;
    campaign_run_ = L.result.run_id;
    if (L.result.validation_run_id > 0) {
      record_quality(L);  // the campaign's run is over: its figures, then the validation run's own
      mark_run(L, L.result.validation_run_id);
      L.result.run_id = L.result.validation_run_id;
      L.next_seq = 0;
    }
    L.event(domain::ValidationEvent{L.result.run_id, plan_.validation.reversals, plan_.validation.seed, validation_points(plan_.validation),
                                    "a seeded random input after the rows, not used to build any table: every table is scored on it"});
  }

  // Motion is supervised: distance / rate, plus the rig's lag, a settle time and the dwell.
  void arm_deadline(double t, double x, const SetpointCommand& cmd) {
    const Segment* seg = seq_.current();
    target_ = cmd.target_mm;
    started_ = t;
    // Plus kHostStallAllowance_s of wall time: a host (or a time-scaled simulator) starved for that
    // long is no servo failure; at time scale 200 it is 300 s of rig time.
    deadline_ = t + std::fabs(cmd.target_mm - x) / cmd.rate_mm_s + settings_.lag_s + settings_.settle_s + (seg ? seg->dwell_s : 0.0) +
                domain::kHostStallAllowance_s * time_scale_;
  }

  bool target_missed(Loop& L, const drivers::RigSample& s) {
    L.ctx.supervisor.hold(s.time_s, "target not reached: held");
    char buf[200];
    std::snprintf(buf, sizeof buf, "target %.3f mm not reached in %.1f s: stopped at %.3f mm (in-position tolerance %.3g mm)", target_, s.time_s - started_,
                  s.displacement_mm, settings_.in_position_mm);
    L.end(CampaignEnd::failed, buf);
    return false;
  }

  // At the end of the schedule, each fot row with a node missing (a hole in its descent) is
  // taken again, from δmin (which wipes the memory as at any row's start), for up to
  // kMaxRowRetakeRounds rounds; a table still incomplete then fails the campaign (run_finish.cpp).
  void retake_rows(Loop& L) {
    if (builder_->complete() || rounds_ >= kMaxRowRetakeRounds) return;
    std::vector<Segment> again;
    nlohmann::json rows = nlohmann::json::array();
    std::vector<Segment> all = schedule(plan_);
    if (adaptive_)
      for (int r : adaptive_->chosen()) all.push_back({builder_->grid().node(r), plan_.ramp_rate_mm_s, plan_.dwell_s, SegmentKind::rise, r});
    for (const Segment& seg : all) {
      if (seg.kind != SegmentKind::rise || row_complete(seg.row) || std::find(rows.begin(), rows.end(), seg.row) != rows.end()) continue;
      rows.push_back(seg.row);
      again.push_back(seg);
      again.push_back({plan_.lo_mm, plan_.ramp_rate_mm_s, plan_.dwell_s, SegmentKind::descent, seg.row});
    }
    if (again.empty()) return;
    ++rounds_;
    seq_.insert_before_current(again);
    domain::RetakeEvent ev;
    ev.rows.emplace(rows.begin(), rows.end()), ev.round = rounds_, ev.why = "a node of each was missing (a hole in the data)";
    L.event(ev);
  }

  // An adaptive campaign's rows are queued: the design's next row, inserted before the validation
  // (or at the end) once every row queued so far is measured. True when one was inserted.
  bool next_design_row(Loop& L, const drivers::RigSample& s) {
    if (!adaptive_ || adaptive_->over()) return false;
    fot_->set_spacing(L.spacing);
    fot_->feed(s.time_s, s.displacement_mm, s.force_N, false);
    fot_->finish();  // the last descent's bottom (node (i, 0)) is the frame at δmin now
    if (fot_->take_descent_completed()) evaluate(L);
    domain::DesignEvent ev;
    std::optional<std::vector<Segment>> row;
    try {  // a design that fails ends the design, not the campaign: the rows measured keep their table
      row = adaptive_->next(*builder_, series_, ev);
    } catch (const std::exception& e) {
      ev = {}, ev.stopped = std::string("the design failed: ") + e.what();
    }
    ev.rig_s = s.time_s - L.mark.t0;
    L.event(ev);
    if (!row) return false;
    seq_.insert_before_current(*row);
    return true;
  }

  // An adaptive campaign's table: the rows it measured, on their own grid (format v2); the fine
  // builder itself while the top row is not measured (its table then fails as incomplete).
  std::shared_ptr<models::OnlineTableBuilder> table_builder() const {
    if (std::optional<models::OnlineTableBuilder> b = models::rows_builder(*builder_)) return std::make_shared<models::OnlineTableBuilder>(std::move(*b));
    return builder_;
  }

  void evaluate(Loop& L) { post_evaluation(L.ctx, L.job.id, adaptive_ ? *table_builder() : *builder_, series_, L.ctx.now_iso()); }

  [[nodiscard]] bool row_complete(int row) const {
    for (int j = 0; j < row; ++j)  // the last descent's bottom comes when the next rise (or the end) turns it
      if (!builder_->identified(row, j) && !(j == 0 && fot_->bottom_pending(row))) return false;
    return true;
  }

  bool collecting() const {
    const Segment* s = seq_.current();
    return s && (s->kind == SegmentKind::rise || s->kind == SegmentKind::descent);
  }

  const domain::Plan& plan_;
  Sequencer seq_;
  domain::SupervisionSettings settings_;
  std::shared_ptr<models::OnlineTableBuilder> builder_;
  std::unique_ptr<OnlineFot> fot_;
  std::optional<AdaptiveRows> adaptive_;
  bool design_done_at_start_ = false;  // a resumed adaptive campaign whose design had stopped
  RunSeries series_, validation_;
  Columns cycle_;  // the training cycle being judged
  double time_scale_ = 1.0;
  ShakedownRule shakedown_;
  std::optional<std::size_t> cycle_start_;  // the sample a training cycle began at
  std::size_t rows_begin_ = 0, halvings_seen_ = 0;
  bool validating_ = false;
  bool validation_to_rerun_ = false;  // a resume: the validation input is driven again, whole (has_work)
  std::int64_t campaign_run_ = 0;
  double target_ = 0, started_ = 0, deadline_ = 1e300;
  double stalled_at_arm_ = 0;
  int rounds_ = 0;
  static constexpr int kMaxRowRetakeRounds = 3;
};
}  // namespace

std::unique_ptr<Strategy> make_ramp_strategy(Loop& L) { return std::make_unique<RampStrategy>(L); }

}  // namespace hystlab::daemon
