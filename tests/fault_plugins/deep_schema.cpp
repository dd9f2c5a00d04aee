// Fault plugin: a parameter schema nested 100,000 levels deep ({"not": {"not": ... {} ...}}). Every
// walk of a schema recurses, and listing it overflowed the host's stack; the host refuses it when it
// reads the metadata, as it refuses a scene nested deeper than 64 levels.
#include <string>

#include "fault_lagrangian.hpp"

namespace {

const char* deep_schema() {
  constexpr std::size_t kDepth = 100000;
  static const std::string text = [] {
    std::string t;
    for (std::size_t i = 0; i < kDepth; ++i) t += "{\"not\": ";
    return t + "{}" + std::string(kDepth, '}');
  }();
  return text.c_str();
}

}  // namespace

class DeepSchema : public varia::test::FaultLagrangian<DeepSchema> {
 public:
  static inline const char* parameter_schema = deep_schema();
  DeepSchema(const nlohmann::json&, const varia::sdk::Context&) {}
};

VARIA_PLUGIN(DeepSchema, lagrangian, fault_deep_schema)
