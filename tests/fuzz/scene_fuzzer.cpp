// libFuzzer target: the scene reader and validator (not the integrator), and plugins' parameter
// schemas. Any input must end in success or in the error the host maps to a clean exit (an
// InputError: exit 2, one message; for a schema, std::invalid_argument: the plugin is refused,
// exit 3); anything else escaping, or any memory or undefined-behaviour error that the sanitizers
// see, is a finding. The bundled plugins' parameter schemas take part, so the registry reads the
// build's plugin directory (VARIA_PLUGIN_DIR).
//
// An input that starts with '!' is a plugin's parameter schema, then a newline, then parameters
// to validate against it (tests/fuzz/regressions/schema-*.json); any other input is a scene.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

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
    const Scene scene = parse_scene(parse_json_text(text));
    validate_parameters(scene, registry);
  } catch (const InputError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  if (!text.empty() && text[0] == '!')
    parameter_schema(text);
  else
    scene(text);
  return 0;
}
