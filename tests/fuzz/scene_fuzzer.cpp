// libFuzzer target: the scene reader and validator (not the integrator). Any input must end in
// success or in an InputError (exit code 2, one message); anything else escaping, or any memory
// or undefined-behaviour error that the sanitizers see, is a finding. The bundled plugins' parameter
// schemas take part, so the registry reads the build's plugin directory (VARIA_PLUGIN_DIR).
#include <cstddef>
#include <cstdint>
#include <string>

#include "errors.hpp"
#include "json_reader.hpp"
#include "registry.hpp"
#include "scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace varia::host;
  static Registry registry({VARIA_PLUGIN_DIR});
  try {
    const Scene scene = parse_scene(parse_json_text(std::string(reinterpret_cast<const char*>(data), size)));
    validate_parameters(scene, registry);
  } catch (const InputError&) {
  }
  return 0;
}
