// A fatal signal (SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT) ends varia with one line on stderr
// that names the plugin file whose code was on the stack, as OpenFOAM's and Blender's crash
// handlers name the failing module; then the signal's default action ends the process. There is
// no isolation: the run ends (docs/security.md, "What a faulty plugin does").
#pragma once

#include <filesystem>

namespace varia::host {

void install_crash_handlers();

// The registry notes each plugin file it loads, so that a crash can name it.
void note_plugin_file(const std::filesystem::path& file);

}  // namespace varia::host
