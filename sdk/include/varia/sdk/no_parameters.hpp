// For plugins that take no parameters: their parameter schema, and the check that none were given
// (the host checks the schema already; this keeps a plugin made directly just as safe).
#pragma once

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace varia::sdk {

inline constexpr const char* kNoParameters = R"({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {},
    "additionalProperties": false
  })";

inline void require_no_parameters(const nlohmann::json& parameters, const char* type) {
  if (!parameters.empty())
    throw std::invalid_argument(std::string(type) + " takes no parameters, got " + parameters.dump());
}

}  // namespace varia::sdk
