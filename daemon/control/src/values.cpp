#include "hystlab/control/values.hpp"

namespace hystlab::control {

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
