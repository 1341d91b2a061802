#pragma once
// A campaign's state and kind: enums inside the program, text only at its edges (the database's
// columns, JSON, the CLI's lines). The text is the stored form: changing it needs a migration.
#include <array>
#include <optional>
#include <string_view>
#include <vector>

namespace hystlab::domain {

enum class CampaignState { queued, held, arming, running, paused, completed, aborted, failed, interrupted };
inline constexpr std::array<CampaignState, 9> kCampaignStates{CampaignState::queued,  CampaignState::held,   CampaignState::arming,
                                                              CampaignState::running, CampaignState::paused, CampaignState::completed,
                                                              CampaignState::aborted, CampaignState::failed, CampaignState::interrupted};
[[nodiscard]] const char* to_string(CampaignState s) noexcept;
// nullopt for any other text.
[[nodiscard]] std::optional<CampaignState> campaign_state_from(std::string_view text) noexcept;
// completed, aborted or failed: nothing more happens to it (interrupted and held can resume).
[[nodiscard]] bool is_final(CampaignState s) noexcept;
// arming, running or paused: the campaign holds its rig.
[[nodiscard]] bool is_active(CampaignState s) noexcept;

// fot: the first-order-transition input (load frames); waveform: a list of points (load frames);
// sine: base excitation at steady frequencies (shakers).
enum class CampaignKind { fot, waveform, sine };
[[nodiscard]] const char* to_string(CampaignKind k) noexcept;
[[nodiscard]] std::optional<CampaignKind> campaign_kind_from(std::string_view text) noexcept;

// A run of a campaign: its own input (training, the rows), or the validation input after it, on
// which the campaign's tables are scored (never used to build them).
enum class RunRole { campaign, validation };
[[nodiscard]] const char* to_string(RunRole r) noexcept;
[[nodiscard]] std::optional<RunRole> run_role_from(std::string_view text) noexcept;

// Where a closed cycle of a run was taken: training loops, the FOT rows (or a waveform's
// points), or the validation input.
enum class LoopPhase { training, rows, validation };
[[nodiscard]] const char* to_string(LoopPhase p) noexcept;

// Operator commands for a campaign, from the API to the rig's thread (estop: the rig's e-stop,
// now; no motion). Text only at the edges (JSON, the database's command events).
enum class CampaignCommand { pause, resume, abort, estop };
[[nodiscard]] const char* to_string(CampaignCommand c) noexcept;
// nullopt for anything else: an unknown command is refused, never taken for an abort.
[[nodiscard]] std::optional<CampaignCommand> campaign_command_from(std::string_view text) noexcept;
// The commands that do something to a campaign in this state, as the daemon carries them out:
// what a page offers (pause a running one; resume a paused, interrupted or held one; abort or
// e-stop any that is not over).
[[nodiscard]] std::vector<CampaignCommand> commands_for(CampaignState s);

// The kind of rig: a load frame (a specimen between grips, displacement and force) or a shaker
// (a mass on the specimen over a moving base). Text at the edges: "load_frame", "shaker".
enum class RigKind { load_frame, shaker };
[[nodiscard]] const char* to_string(RigKind k) noexcept;
[[nodiscard]] std::optional<RigKind> rig_kind_from(std::string_view text) noexcept;

}  // namespace hystlab::domain
