#include "hystlab/domain/campaign.hpp"

namespace hystlab::domain {

const char* to_string(CampaignState s) noexcept {
  switch (s) {
    case CampaignState::queued:
      return "queued";
    case CampaignState::held:
      return "held";
    case CampaignState::arming:
      return "arming";
    case CampaignState::running:
      return "running";
    case CampaignState::paused:
      return "paused";
    case CampaignState::completed:
      return "completed";
    case CampaignState::aborted:
      return "aborted";
    case CampaignState::failed:
      return "failed";
    case CampaignState::interrupted:
      return "interrupted";
  }
  return "?";
}

std::optional<CampaignState> campaign_state_from(std::string_view text) noexcept {
  for (const CampaignState s : kCampaignStates)
    if (text == to_string(s)) return s;
  return std::nullopt;
}

bool is_final(CampaignState s) noexcept { return s == CampaignState::completed || s == CampaignState::aborted || s == CampaignState::failed; }

bool is_active(CampaignState s) noexcept { return s == CampaignState::arming || s == CampaignState::running || s == CampaignState::paused; }

const char* to_string(CampaignKind k) noexcept {
  switch (k) {
    case CampaignKind::fot:
      return "fot";
    case CampaignKind::waveform:
      return "waveform";
    case CampaignKind::sine:
      return "sine";
  }
  return "?";
}

std::optional<CampaignKind> campaign_kind_from(std::string_view text) noexcept {
  for (const CampaignKind k : {CampaignKind::fot, CampaignKind::waveform, CampaignKind::sine})
    if (text == to_string(k)) return k;
  return std::nullopt;
}

const char* to_string(RunRole r) noexcept { return r == RunRole::validation ? "validation" : "campaign"; }

std::optional<RunRole> run_role_from(std::string_view text) noexcept {
  for (const RunRole r : {RunRole::campaign, RunRole::validation})
    if (text == to_string(r)) return r;
  return std::nullopt;
}

const char* to_string(LoopPhase p) noexcept {
  switch (p) {
    case LoopPhase::training:
      return "training";
    case LoopPhase::rows:
      return "rows";
    case LoopPhase::validation:
      return "validation";
  }
  return "?";
}

const char* to_string(CampaignCommand c) noexcept {
  switch (c) {
    case CampaignCommand::pause:
      return "pause";
    case CampaignCommand::resume:
      return "resume";
    case CampaignCommand::abort:
      return "abort";
    case CampaignCommand::estop:
      return "estop";
  }
  return "?";
}

std::optional<CampaignCommand> campaign_command_from(std::string_view text) noexcept {
  for (const CampaignCommand c : {CampaignCommand::pause, CampaignCommand::resume, CampaignCommand::abort, CampaignCommand::estop})
    if (text == to_string(c)) return c;
  return std::nullopt;
}

std::vector<CampaignCommand> commands_for(domain::CampaignState s) {
  using S = domain::CampaignState;
  if (domain::is_final(s)) return {};
  std::vector<CampaignCommand> out;
  if (s == S::running) out.push_back(CampaignCommand::pause);
  if (s == S::paused || s == S::interrupted || s == S::held) out.push_back(CampaignCommand::resume);
  // An interrupted campaign can be ended too (it was answered 202 and then ignored): abort ends
  // it where it is; e-stop also latches its rig.
  out.push_back(CampaignCommand::abort);
  out.push_back(CampaignCommand::estop);
  return out;
}

const char* to_string(RigKind k) noexcept { return k == RigKind::shaker ? "shaker" : "load_frame"; }

std::optional<RigKind> rig_kind_from(std::string_view text) noexcept {
  if (text == "load_frame") return RigKind::load_frame;
  if (text == "shaker") return RigKind::shaker;
  return std::nullopt;
}

}  // namespace hystlab::domain
