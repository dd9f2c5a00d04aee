#include "crash.hpp"

#include <dlfcn.h>
#include <execinfo.h>
#include <sys/stat.h>
#include <ucontext.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <cstring>

#include "errors.hpp"
#include "output.hpp"

namespace varia::host {

namespace {

// The plugin files noted, by identity: stat(2) is async-signal-safe, comparing paths is not needed.
constexpr int kMaxPlugins = 256;
struct Noted {
  dev_t device;
  ino_t inode;
};
Noted noted[kMaxPlugins];
volatile std::sig_atomic_t noted_count = 0;

volatile std::sig_atomic_t command_running = 0;
CrashSafeOutput* volatile watched = nullptr;

alignas(16) char alternate_stack[1 << 16];  // a stack overflow still runs the handler

// One line of at most a fixed length, built without allocating and written with one write(2).
class Line {
 public:
  Line& add(const char* text) {
    while (*text != '\0' && size_ < sizeof text_ - 1) text_[size_++] = *text++;
    return *this;
  }
  void write() {  // add() leaves room for the newline
    text_[size_] = '\n';
    (void)!::write(STDERR_FILENO, text_, size_ + 1);
  }

 private:
  char text_[4096];
  std::size_t size_ = 0;
};

constexpr const char* kPrefix = "varia: error: plugin fault: ";
constexpr const char* kAftermath =
    "; varia ends with exit code 3, the trajectory written ends with a whole row, no run record is written";

const char* signal_text(int signal) {
  switch (signal) {
    case SIGSEGV: return "SIGSEGV (invalid memory access, or a stack overflow)";
    case SIGBUS: return "SIGBUS (bus error)";
    case SIGFPE: return "SIGFPE (arithmetic fault)";
    case SIGILL: return "SIGILL (illegal instruction)";
    default: return "SIGABRT (abort)";
  }
}

// The file of the noted plugin this address lies in, or nullptr. dladdr is not on POSIX's list of
// async-signal-safe functions: it takes the dynamic loader's lock, recursively, so it works in a
// handler of the thread that holds it (a crash inside dlopen) and varia has no other thread.
const char* plugin_at(const void* address) {
  Dl_info info{};
  struct stat status {};
  if (address == nullptr || ::dladdr(address, &info) == 0 || info.dli_fname == nullptr ||
      ::stat(info.dli_fname, &status) != 0)
    return nullptr;
  for (int k = 0; k < noted_count; ++k)
    if (noted[k].device == status.st_dev && noted[k].inode == status.st_ino) return info.dli_fname;
  return nullptr;
}

// The file of the first noted plugin among the stack's frames, or nullptr. backtrace is not on
// POSIX's list either: install_crash_handlers loads its unwinder beforehand, so that it does not
// allocate here.
const char* plugin_on_stack() {
  void* frames[128];
  const int count = ::backtrace(frames, 128);
  for (int i = 0; i < count; ++i)
    if (const char* plugin = plugin_at(frames[i])) return plugin;
  return nullptr;
}

// The instruction that faulted, from the signal's context.
const void* faulting_instruction(const void* context) {
  const auto* uc = static_cast<const ucontext_t*>(context);
#if defined(__x86_64__)
  return reinterpret_cast<const void*>(uc->uc_mcontext.gregs[REG_RIP]);
#elif defined(__aarch64__)
  return reinterpret_cast<const void*>(uc->uc_mcontext.pc);
#else
  (void)uc;
  return nullptr;
#endif
}

// A plugin ended the process: the trajectory is left whole, the line names it, exit code 3.
[[noreturn]] void end_for_plugin(Line& line) {
  if (CrashSafeOutput* output = watched) output->end_on_crash();
  line.add(kAftermath).write();
  ::_exit(kExitPlugin);
}

void on_fatal_signal(int signal, siginfo_t*, void* context) {
  const char* plugin = plugin_at(faulting_instruction(context));
  if (plugin == nullptr) plugin = plugin_on_stack();
  Line line;
  line.add(kPrefix).add("fatal signal ").add(signal_text(signal));
  if (plugin != nullptr) end_for_plugin(line.add(" in a call to the plugin ").add(plugin));
  line.add(" with no plugin code on the stack (a fault of varia itself)").write();
  std::signal(signal, SIG_DFL);  // SA_RESETHAND did so already; also for a handler run from raise
  std::raise(signal);
}

// Registered with atexit and at_quick_exit: while a command runs, only a plugin calls them.
void on_exit_during_command() {
  if (command_running == 0) return;
  const char* plugin = plugin_on_stack();
  Line line;
  line.add(kPrefix);
  if (plugin != nullptr)
    line.add("the plugin ").add(plugin).add(" called exit or quick_exit during the command");
  else
    line.add("exit or quick_exit was called during the command by code outside varia and its plugin files");
  end_for_plugin(line);
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
  action.sa_sigaction = on_fatal_signal;
  action.sa_flags = SA_SIGINFO | SA_ONSTACK | SA_RESETHAND;
  sigemptyset(&action.sa_mask);
  for (int signal : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) ::sigaction(signal, &action, nullptr);
  std::atexit(on_exit_during_command);
  std::at_quick_exit(on_exit_during_command);
}

void note_plugin_file(const std::filesystem::path& file) {
  struct stat status {};
  if (noted_count >= kMaxPlugins || ::stat(file.c_str(), &status) != 0) return;
  noted[noted_count] = Noted{status.st_dev, status.st_ino};
  noted_count = noted_count + 1;
}

CommandInFlight::CommandInFlight() { command_running = 1; }
CommandInFlight::~CommandInFlight() { command_running = 0; }

void watch_trajectory(CrashSafeOutput* output) { watched = output; }

}  // namespace varia::host
