// libFuzzer target: the scene reader and validator (not the integrator), plugins' parameter
// schemas, and the command line. Any input must end in success or in the error the host maps to a
// clean exit (an InputError: exit 2, one message; for a schema, std::invalid_argument: the plugin
// is refused, exit 3); anything else escaping, or any memory or undefined-behaviour error that the
// sanitizers see, is a finding. The bundled plugins' parameter schemas take part, so the registry
// reads the build's plugin directory (VARIA_PLUGIN_DIR).
//
// An input that starts with '!' is a plugin's parameter schema, then a newline, then parameters
// to validate against it (tests/fuzz/regressions/schema-*.json). One that starts with '$' is a
// command line, one word a line (tests/fuzz/regressions/cli-*.txt): parsed as varia parses it, and
// the quick commands (plugins, validate, ld, run) run, in a directory of their own holding short
// scenes, with words that could name a file outside it ('/' or "..") refused. Any other input is
// a scene.
#include <fcntl.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli.hpp"
#include "errors.hpp"
#include "json_reader.hpp"
#include "json_schema.hpp"
#include "registry.hpp"
#include "scene.hpp"

namespace {

using namespace varia::host;

// As the registry checks a plugin's schema when it lists it, then as a scene's parameters are
// validated against it.
void parameter_schema(const std::string& text) {
  const auto newline = text.find('\n');
  const std::string schema_text = text.substr(1, newline == std::string::npos ? std::string::npos : newline - 1);
  const std::string parameters = newline == std::string::npos ? "{}" : text.substr(newline + 1);
  try {
    const auto schema = parse_json_text(schema_text);
    check_parameter_schema(schema);
    const SchemaValidator validator(schema);
    validator.validate(parse_json_text(parameters), "/system/lagrangian");
  } catch (const std::invalid_argument&) {  // the plugin is refused
  } catch (const InputError&) {
  }
}

void scene(const std::string& text) {
  static Registry registry({VARIA_PLUGIN_DIR});
  try {
    Scene scene = parse_scene(parse_json_text(text));
    validate_parameters(scene, registry);
  } catch (const InputError&) {
  }
}

namespace fs = std::filesystem;

// The scenes the command lines name: bundled ones cut to 20 steps (so that `run` is quick), and a
// bad one, under short names.
const std::pair<const char*, const char*> kScenes[] = {
    {"a.json", "scenes/default.json"},
    {"b.json", "scenes/kepler-galerkin.json"},
    {"c.json", "scenes/paper/heavy-top-lgvi.json"},
    {"d.json", "scenes/bad/mass-zero.json"},
};

// The directory the commands run in, made once: stdout and stderr (which libFuzzer's
// -close_fd_mask=3 closes) opened on /dev/null, the bundled plugins on VARIA_PLUGIN_PATH (the
// fuzzer is not beside them).
const fs::path& sandbox() {
  static const fs::path directory = [] {
    for (int fd = 1; fd <= 2; ++fd)
      if (::fcntl(fd, F_GETFD) < 0) ::dup2(::open("/dev/null", O_WRONLY), fd);
    ::setenv("VARIA_PLUGIN_PATH", VARIA_PLUGIN_DIR, 1);
    // run.sh names one in the build tree (and removes it); else one in /tmp, removed at exit.
    if (const char* given = std::getenv("VARIA_FUZZ_SANDBOX")) {
      fs::create_directories(given);
      return fs::absolute(given);
    }
    char name[] = "/tmp/varia-fuzz-cli-XXXXXX";
    if (::mkdtemp(name) == nullptr) std::abort();
    std::atexit([] {
      std::error_code ec;
      fs::remove_all(sandbox(), ec);
    });
    return fs::path(name);
  }();
  return directory;
}

// Empties the sandbox, writes its scenes again (a command may have overwritten one) and makes it
// the working directory.
void reset_sandbox() {
  for (const auto& entry : fs::directory_iterator(sandbox())) fs::remove_all(entry.path());
  for (const auto& [name, source] : kScenes) {
    nlohmann::json document = read_json_file(fs::path(VARIA_SOURCE_DIR) / source);
    document.erase("t_end");
    document["steps"] = 20;
    std::ofstream(sandbox() / name) << document.dump();
  }
  fs::current_path(sandbox());
}

int command_line(const std::string& text) {
  std::vector<std::string> words{"varia"};
  for (std::size_t at = 1; at <= text.size();) {
    const auto end = std::min(text.find('\n', at), text.size());
    words.push_back(text.substr(at, end - at));
    if (words.back().find('/') != std::string::npos || words.back() == ".." || words.size() > 32) return -1;
    at = end + 1;
  }
  const fs::path previous = fs::current_path();
  reset_sandbox();
  std::vector<char*> argv;
  for (auto& word : words) argv.push_back(word.data());
  argv.push_back(nullptr);
  run_command_line(static_cast<int>(words.size()), argv.data(), [](const std::string& command) {
    return command == "plugins" || command == "validate" || command == "ld" || command == "run";
  });
  fs::current_path(previous);  // libFuzzer's paths may be relative
  return 0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  if (!text.empty() && text[0] == '!') {
    parameter_schema(text);
    return 0;
  }
  if (!text.empty() && text[0] == '$') return command_line(text);
  scene(text);
  return 0;
}
