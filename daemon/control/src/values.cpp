#include "hystlab/control/values.hpp"

namespace hystlab::control {

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

std::vector<CampaignCommand> commands_for(db::CampaignState s) {
  using S = db::CampaignState;
  if (db::is_final(s)) return {};
  std::vector<CampaignCommand> out;
  if (s == S::running) out.push_back(CampaignCommand::pause);
  if (s == S::paused || s == S::interrupted || s == S::held) out.push_back(CampaignCommand::resume);
  // An interrupted campaign can be ended too (it was answered 202 and then ignored): abort ends
  // it where it is; e-stop also latches its rig.
  out.push_back(CampaignCommand::abort);
  out.push_back(CampaignCommand::estop);
  return out;
}

const char* to_string(CommandOutcome::Result r) noexcept {
  using R = CommandOutcome::Result;
  switch (r) {
    case R::done:
      return "done";
    case R::pending:
      return "pending";
    case R::conflict:
      return "conflict";
    case R::unreachable:
      return "unreachable";
    case R::refused:
      return "refused";
  }
  return "?";
}

}  // namespace hystlab::control
