// What varia does when a plugin ends the process under it (docs/security.md, "What a faulty plugin
// does"). Plugins run in the varia process, so nothing isolates them; these handlers only make the
// end of the process say which plugin ended it, and leave the outputs whole:
//
// - A fatal signal (SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT; handled on an alternate stack, so a
//   stack overflow too) whose faulting instruction, or a frame of whose stack, lies in a plugin
//   file: one line names the file, the trajectory is left whole (watch_trajectory), and varia
//   ends with exit code 3 (spec: plugin fault). With no plugin code on the stack (a fault of varia
//   itself) the line says so and the signal's default action ends varia (e.g. 139, a core dump).
// - exit() or quick_exit() called while a command runs (varia itself never calls them; its
//   commands return to main): one line names the plugin on the stack, the trajectory is left
//   whole, and varia ends with exit code 3, whatever status the plugin asked for.
//
// Nothing here costs anything per call into a plugin: the plugin is found from the program
// counter and the stack (dladdr) when the process ends, among the files the registry noted.
#pragma once

#include <filesystem>

namespace varia::host {

class CrashSafeOutput;

void install_crash_handlers();

// The registry notes each plugin file before it loads it, so that a crash can name it.
void note_plugin_file(const std::filesystem::path& file);

// While one lives, the command is running: an exit() or quick_exit() is a plugin fault.
class CommandInFlight {
 public:
  CommandInFlight();
  ~CommandInFlight();
  CommandInFlight(const CommandInFlight&) = delete;
  CommandInFlight& operator=(const CommandInFlight&) = delete;
};

// The trajectory being written (nullptr: none), which the handlers leave whole before the process
// ends (CrashSafeOutput::end_on_crash: the CSV writes its buffered whole rows, the HDF5 file keeps
// its flushed blocks).
void watch_trajectory(CrashSafeOutput* output);

}  // namespace varia::host
