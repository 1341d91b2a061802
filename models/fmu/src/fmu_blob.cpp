// The FMU runtime binary, embedded at build time (.incbin of the module target's output), so
// that the CLI and the daemon write FMUs without looking for files beside themselves.
#include <string_view>

#include "hystlab/fmu/fmu_archive.hpp"

#ifndef HYSTLAB_FMU_RUNTIME_PATH
#error "HYSTLAB_FMU_RUNTIME_PATH: the path of hystlab_element.so (set by models/fmu/CMakeLists.txt)"
#endif

asm(".pushsection .rodata\n"
    ".balign 16\n"
    ".globl hystlab_fmu_runtime_start\n"
    ".hidden hystlab_fmu_runtime_start\n"
    "hystlab_fmu_runtime_start:\n"
    ".incbin \"" HYSTLAB_FMU_RUNTIME_PATH
    "\"\n"
    ".globl hystlab_fmu_runtime_end\n"
    ".hidden hystlab_fmu_runtime_end\n"
    "hystlab_fmu_runtime_end:\n"
    ".popsection\n");

extern "C" const char hystlab_fmu_runtime_start[];
extern "C" const char hystlab_fmu_runtime_end[];

namespace hystlab::fmu {
std::string_view fmu_runtime_binary() { return {hystlab_fmu_runtime_start, static_cast<std::size_t>(hystlab_fmu_runtime_end - hystlab_fmu_runtime_start)}; }
}  // namespace hystlab::fmu
