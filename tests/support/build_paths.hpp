#pragma once
// Where a test finds the project's programs and files: by paths relative to the build tree (and
// from it to the source tree), compiled in by hystlab_test_paths (tests/CMakeLists.txt) and
// resolved when the test runs, against the test program's own location (/proc/self/exe).
//
// Why not absolute paths: a definition such as HYSTLABD="/home/a/hystlab/build/daemon/hystlabd"
// makes every object that sees it differ between two clones of one commit, so a compiler cache
// misses those objects in a fresh folder (issue 40: a warm run of a new clone; stop 44's fourth
// clean clone rebuilt the test batches that named the clone's path).
//
// The names stay the macros the tests always used (HYSTLABD, HYSTLAB_SIM, HYSTLAB_CLI,
// HYSTLAB_CRASH_WRITER, HYSTLAB_CAPI_LIB, HYSTLAB_CAPI_INCLUDE, HYSTLAB_MAPS, HYSTLAB_API_DOC,
// HYSTLAB_SOURCE_DIR); each is now a
// std::string expression, not a string literal.
#include <filesystem>
#include <string>

#ifndef HYSTLAB_EXE_TO_BUILD
#error "build_paths.hpp: the target needs hystlab_test_paths() in its CMakeLists.txt"
#endif

namespace hystlab::test_support {

// The build tree's top, from this program's folder.
inline const std::filesystem::path& build_root() {
  static const std::filesystem::path root = (std::filesystem::read_symlink("/proc/self/exe").parent_path() / HYSTLAB_EXE_TO_BUILD).lexically_normal();
  return root;
}
inline std::string in_build(const char* relative) { return (build_root() / relative).lexically_normal().string(); }
inline std::string in_source(const char* relative) { return (build_root() / HYSTLAB_BUILD_TO_SOURCE / relative).lexically_normal().string(); }

}  // namespace hystlab::test_support

#ifdef HYSTLABD_REL
#define HYSTLABD ::hystlab::test_support::in_build(HYSTLABD_REL)
#endif
#ifdef HYSTLAB_SIM_REL
#define HYSTLAB_SIM ::hystlab::test_support::in_build(HYSTLAB_SIM_REL)
#endif
#ifdef HYSTLAB_CLI_REL
#define HYSTLAB_CLI ::hystlab::test_support::in_build(HYSTLAB_CLI_REL)
#endif
#ifdef HYSTLAB_CRASH_WRITER_REL
#define HYSTLAB_CRASH_WRITER ::hystlab::test_support::in_build(HYSTLAB_CRASH_WRITER_REL)
#endif
#ifdef HYSTLAB_CAPI_LIB_REL
#define HYSTLAB_CAPI_LIB ::hystlab::test_support::in_build(HYSTLAB_CAPI_LIB_REL)
#endif
#define HYSTLAB_CAPI_INCLUDE ::hystlab::test_support::in_source("models/capi/include")
#define HYSTLAB_MAPS ::hystlab::test_support::in_source("protocols/maps")
#define HYSTLAB_API_DOC ::hystlab::test_support::in_source("docs/API.md")
#define HYSTLAB_SOURCE_DIR ::hystlab::test_support::in_source(".")
