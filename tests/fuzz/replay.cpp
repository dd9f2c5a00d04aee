// Replays inputs through the scene fuzzer's target (scene_fuzzer.cpp) without libFuzzer, built by
// the project's own compiler into the quick suite, so that every test build compiles and links
// the harness against the host as it is, and the corpus the fuzzer is seeded with (the bad scenes,
// tests/fuzz/regressions) still ends cleanly through it: an input that lets anything escape the
// target aborts the replay. libFuzzer's build (clang, sanitizers) and run are `ctest -L fuzz`.
// Usage: scene_fuzzer_replay FILE_OR_DIRECTORY... (stdout discarded; stderr keeps the messages).
#include <fcntl.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

void replay(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::filesystem::path> files;
  for (int i = 1; i < argc; ++i) {
    if (!std::filesystem::is_directory(argv[i])) {
      files.emplace_back(argv[i]);
      continue;
    }
    for (const auto& entry : std::filesystem::recursive_directory_iterator(argv[i]))
      if (entry.is_regular_file()) files.push_back(entry.path());
  }
  ::dup2(::open("/dev/null", O_WRONLY), STDOUT_FILENO);  // what the replayed commands print, as libFuzzer's -close_fd_mask=1
  for (const auto& file : files) replay(file);
  std::fprintf(stderr, "replayed %zu inputs\n", files.size());
  return files.empty() ? 1 : 0;
}
