// Fault plugin: a parameter schema that valijson cannot read ("type" must be a name). The host
// refuses this plugin when it lists it (exit 3 naming the file for a scene that needs it); the
// others go on working.
#include "fault_lagrangian.hpp"

class BadSchema : public varia::test::FaultLagrangian<BadSchema> {
 public:
  static constexpr const char* parameter_schema = R"({"type": 5})";
  BadSchema(const nlohmann::json&, const varia::sdk::Context&) {}
};

VARIA_PLUGIN(BadSchema, lagrangian, fault_bad_schema)
