// What the Runge-Kutta one_step plugins share: the parameter schema of a method without
// parameters, and the check that none were given.
#pragma once

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace varia::plugins {

inline constexpr const char* kNoParameters = R"({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {},
    "additionalProperties": false
  })";

inline void require_no_parameters(const nlohmann::json& parameters, const char* type) {
  if (!parameters.empty())
    throw std::invalid_argument(std::string(type) + " takes no parameters, got " +
                                parameters.dump());
}

}  // namespace varia::plugins
