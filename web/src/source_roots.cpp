// The source tree's page folders, compiled in as the fallback when none is configured or installed
// (web/CMakeLists.txt gives the paths; see api_support.hpp).
#include "api_support.hpp"

namespace hystlab::web {
const char* source_web_root() noexcept { return HYSTLAB_WEB_ROOT; }
const char* source_vendor_root() noexcept { return HYSTLAB_VENDOR_ROOT; }
}  // namespace hystlab::web
