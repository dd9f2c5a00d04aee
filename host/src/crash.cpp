#include "crash.hpp"

#include <dlfcn.h>
#include <execinfo.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <cstring>

namespace varia::host {

namespace {

// The plugin files loaded, by identity (stat is async-signal-safe, comparing paths is not needed).
constexpr int kMaxPlugins = 256;
struct Noted {
  dev_t device;
  ino_t inode;
};
Noted noted[kMaxPlugins];
volatile std::sig_atomic_t noted_count = 0;

alignas(16) char alternate_stack[1 << 16];  // a stack overflow still runs the handler

void put(const char* text) { (void)!::write(STDERR_FILENO, text, std::strlen(text)); }

const char* signal_text(int signal) {
  switch (signal) {
    case SIGSEGV: return "SIGSEGV (invalid memory access)";
    case SIGBUS: return "SIGBUS (bus error)";
    case SIGFPE: return "SIGFPE (arithmetic fault)";
    case SIGILL: return "SIGILL (illegal instruction)";
    default: return "SIGABRT (abort)";
  }
}

// The file of the first noted plugin among the stack's frames, or nullptr.
const char* plugin_on_stack() {
  void* frames[64];
  const int count = ::backtrace(frames, 64);
  for (int i = 0; i < count; ++i) {
    Dl_info info{};
    struct stat status {};
    if (::dladdr(frames[i], &info) == 0 || info.dli_fname == nullptr || ::stat(info.dli_fname, &status) != 0)
      continue;
    for (int k = 0; k < noted_count; ++k)
      if (noted[k].device == status.st_dev && noted[k].inode == status.st_ino) return info.dli_fname;
  }
  return nullptr;
}

void on_fatal_signal(int signal) {
  put("varia: error: plugin fault: fatal signal ");
  put(signal_text(signal));
  if (const char* plugin = plugin_on_stack(); plugin != nullptr) {
    put(" in a call to the plugin ");
    put(plugin);
  } else {
    put(" with no plugin code on the stack (a fault of varia itself)");
  }
  put("; the trajectory on disk ends with the last whole rows written, no run record\n");
  std::signal(signal, SIG_DFL);
  std::raise(signal);
}

}  // namespace

void install_crash_handlers() {
  void* warm[1];
  ::backtrace(warm, 1);  // loads the unwinder now, not inside a handler
  stack_t stack{};
  stack.ss_sp = alternate_stack;
  stack.ss_size = sizeof alternate_stack;
  ::sigaltstack(&stack, nullptr);
  struct sigaction action {};
  action.sa_handler = on_fatal_signal;
  action.sa_flags = SA_ONSTACK | SA_RESETHAND;
  sigemptyset(&action.sa_mask);
  for (int signal : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) ::sigaction(signal, &action, nullptr);
}

void note_plugin_file(const std::filesystem::path& file) {
  struct stat status {};
  if (noted_count >= kMaxPlugins || ::stat(file.c_str(), &status) != 0) return;
  noted[noted_count] = Noted{status.st_dev, status.st_ino};
  noted_count = noted_count + 1;
}

}  // namespace varia::host
