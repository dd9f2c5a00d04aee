#include "json_schema.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <set>
#include <string_view>
// valijson reports an unusable schema by an exception (else it aborts the program).
#define VALIJSON_USE_EXCEPTIONS 1
#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validator.hpp>
#include <vector>

#include "errors.hpp"

namespace varia::host {

using nlohmann::json;

struct SchemaValidator::Impl {
  json document;
  valijson::Schema schema;
};

namespace {

// One violation reported by valijson, as a path of instance keys and what happened there.
struct Violation {
  // In order of preference at the same depth; wrapper: "a child failed" and nothing else.
  enum Kind { leaf, unexpected, missing, wrapper };
  std::vector<std::string> tokens;
  Kind kind = leaf;
  std::string name;  // the key named by a missing/unexpected/wrapper message
};

// The text between the last pair of single quotes of a valijson message.
std::string quoted(const std::string& text) {
  const auto close = text.rfind('\'');
  const auto open = close == std::string::npos || close == 0 ? std::string::npos : text.rfind('\'', close - 1);
  return open == std::string::npos ? std::string() : text.substr(open + 1, close - open - 1);
}

bool starts_with(const std::string& text, std::string_view prefix) {
  return std::string_view(text).substr(0, prefix.size()) == prefix;
}

Violation classify(const valijson::ValidationResults::Error& error) {
  Violation v;
  for (const auto& item : error.context)
    if (item.size() >= 2 && item.front() == '[' && item.back() == ']')
      v.tokens.push_back(item.substr(1, item.size() - 2));
  const std::string& text = error.description;
  const auto add_name = [&](Violation::Kind kind) {
    v.kind = kind;
    v.name = quoted(text);
    v.tokens.push_back(v.name);
  };
  if (starts_with(text, "Missing required property")) {
    add_name(Violation::missing);
  } else if (starts_with(text, "Object contains a property that could not be validated")) {
    add_name(Violation::unexpected);
  } else if (starts_with(text, "Failed to validate against schema associated with property name")) {
    add_name(Violation::wrapper);
  } else if (starts_with(text, "Failed to validate item #")) {
    v.kind = Violation::wrapper;
    v.tokens.push_back(text.substr(25, text.find(' ', 25) - 25));
  } else if (starts_with(text, "Failed to validate")) {
    v.kind = Violation::wrapper;
  }
  return v;
}

// The most specific violation: the deepest one, and among those a direct one before a wrapper.
Violation most_specific(const valijson::ValidationResults& results) {
  Violation best;
  bool have = false;
  for (const auto& error : results) {
    Violation v = classify(error);
    const bool deeper = v.tokens.size() > best.tokens.size();
    const bool preferred = v.tokens.size() == best.tokens.size() && v.kind < best.kind;
    if (!have || deeper || preferred) best = std::move(v), have = true;
  }
  return best;
}

std::string escape_token(const std::string& token) {
  std::string out;
  for (char c : token) out += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
  return out;
}

std::string pointer_of(const std::vector<std::string>& tokens, std::size_t count) {
  std::string pointer;
  for (std::size_t i = 0; i < count; ++i) pointer += "/" + escape_token(tokens[i]);
  return pointer;
}

// Schema navigation, enough to find the description of the schema that applies at an instance
// location: local "$ref", "properties", "items", "additionalProperties" and the branches of
// "allOf", "oneOf" and "anyOf".
const json* resolve(const json& document, const json* node) {
  for (int depth = 0; node && node->is_object() && node->contains("$ref") && depth < 16; ++depth) {
    const auto& ref = (*node)["$ref"];
    if (!ref.is_string() || !starts_with(ref.get<std::string>(), "#")) return nullptr;
    const json::json_pointer pointer(ref.get<std::string>().substr(1));
    node = document.contains(pointer) ? &document.at(pointer) : nullptr;
  }
  return node;
}

const json* child(const json& document, const json* node, const std::string& token) {
  node = resolve(document, node);
  if (node == nullptr || !node->is_object()) return nullptr;
  if (auto it = node->find("properties"); it != node->end() && it->is_object() && it->contains(token))
    return &(*it)[token];
  if (auto it = node->find("items"); it != node->end() && it->is_object()) return &*it;
  for (const char* branches : {"allOf", "oneOf", "anyOf"})
    if (auto it = node->find(branches); it != node->end() && it->is_array())
      for (const auto& branch : *it)
        if (const json* found = child(document, &branch, token)) return found;
  if (auto it = node->find("additionalProperties"); it != node->end() && it->is_object()) return &*it;
  return nullptr;
}

const json* schema_at(const json& document, const std::vector<std::string>& tokens, std::size_t count) {
  const json* node = &document;
  for (std::size_t i = 0; i < count && node != nullptr; ++i) node = child(document, node, tokens[i]);
  return node;
}

// " >= 2 and <= 64"
std::string bounds(const json& node) {
  static const std::pair<const char*, const char*> keywords[] = {
      {"minimum", ">="}, {"exclusiveMinimum", ">"}, {"maximum", "<="}, {"exclusiveMaximum", "<"}};
  std::vector<std::string> parts;
  for (const auto& [key, op] : keywords)
    if (node.contains(key) && node[key].is_number()) parts.push_back(fmt::format("{} {}", op, node[key].dump()));
  return parts.empty() ? "" : fmt::format(" {}", fmt::join(parts, " and "));
}

// The shape a schema asks for, from its keywords: "a number > 0", "one of \"a\", \"b\"", ...
std::string shape(const json& document, const json* node) {
  node = resolve(document, node);
  if (node == nullptr || !node->is_object()) return "";
  if (auto it = node->find("enum"); it != node->end() && it->is_array()) {
    std::vector<std::string> names;
    for (const auto& value : *it) names.push_back(value.dump());
    return fmt::format("one of {}", fmt::join(names, ", "));
  }
  const auto type = node->find("type");
  if (type == node->end() || !type->is_string()) {
    const auto all = node->find("allOf");
    return all != node->end() && all->is_array() && all->size() == 1 ? shape(document, &(*all)[0]) : "";
  }
  const std::string name = *type;
  const std::string article = name == "integer" || name == "object" || name == "array" ? "an " : "a ";
  return article + name + bounds(*node);
}

// What a schema expects, in words: its shape, with its "description" in parentheses.
std::string describe(const json& document, const json* node) {
  const std::string form = shape(document, node);
  const json* resolved = resolve(document, node);
  std::string description;
  for (const json* n : {node, resolved})
    if (description.empty() && n && n->is_object() && n->contains("description") && (*n)["description"].is_string())
      description = (*n)["description"];
  if (form.empty()) return description.empty() ? "a valid value" : description;
  return description.empty() ? form : fmt::format("{} ({})", form, description);
}

std::string allowed_keys(const json& document, const json* node) {
  node = resolve(document, node);
  std::vector<std::string> keys;
  if (node && node->is_object() && node->contains("properties") && (*node)["properties"].is_object())
    for (const auto& [key, value] : (*node)["properties"].items()) keys.push_back(key);
  if (keys.empty()) return "no keys are allowed here";
  return fmt::format("the keys allowed here are: {}", fmt::join(keys, ", "));
}

const json* value_at(const json& instance, const std::string& pointer) {
  try {
    const json::json_pointer p(pointer);
    return instance.contains(p) ? &instance.at(p) : nullptr;
  } catch (const json::exception&) {
    return nullptr;
  }
}

std::string message(const json& document, const json& instance, const Violation& v,
                    const std::string& prefix) {
  const std::size_t n = v.tokens.size();
  const std::string relative = pointer_of(v.tokens, n);
  const std::string pointer = prefix + (relative.empty() && prefix.empty() ? "/" : relative);
  const std::string expected = describe(document, schema_at(document, v.tokens, n));
  const json* value = value_at(instance, relative);
  const std::string found = value ? brief(*value) : "";
  switch (v.kind) {
    case Violation::missing:
      return fmt::format("{}: missing; expected {}", pointer, expected);
    case Violation::unexpected:
      return fmt::format("{}: unknown key '{}'; {}", pointer, v.name,
                         allowed_keys(document, schema_at(document, v.tokens, n - 1)));
    case Violation::wrapper:
      if (!v.name.empty()) return fmt::format("{}: not allowed here (found {}); expected {}", pointer, found, expected);
      [[fallthrough]];
    case Violation::leaf:
      break;
  }
  return fmt::format("{}: expected {}{}", pointer, expected, found.empty() ? "" : "; found " + found);
}

// ---- what valijson is not given ------------------------------------------------------------------

// Keywords a plugin's parameter schema may not use: references (remote ones would be fetched, a
// self reference recurses without end), regular expressions (std::regex's matching time and
// stack depth are unbounded in the input's length) and uniqueItems (valijson compares every pair
// of items, and in a branch such as allOf the host cannot check them first: 16,000 items took
// seconds). docs/security.md, "Plugins".
void check_plugin_schema(const json& node, const std::string& pointer) {
  if (node.is_boolean()) return;
  if (!node.is_object()) throw std::invalid_argument(fmt::format("{}: expected a schema (an object)", pointer));
  static const std::set<std::string> refused{"$ref",   "$id",    "id",         "pattern", "patternProperties",
                                             "format", "uniqueItems"};
  static const std::set<std::string> schema_maps{"properties", "definitions", "$defs", "dependencies"};
  static const std::set<std::string> schema_values{"items", "additionalItems", "additionalProperties", "not",
                                                   "contains", "propertyNames", "if", "then", "else",
                                                   "allOf", "anyOf", "oneOf"};
  for (const auto& [key, value] : node.items()) {
    const std::string at = pointer + "/" + escape_token(key);
    if (refused.count(key) != 0)
      throw std::invalid_argument(fmt::format("{}: the keyword '{}' is not allowed in a parameter schema", at, key));
    if (schema_maps.count(key) != 0 && value.is_object())
      for (const auto& [name, schema] : value.items())
        if (!schema.is_array()) check_plugin_schema(schema, at + "/" + escape_token(name));
    if (schema_values.count(key) != 0) {
      if (value.is_array())
        for (std::size_t i = 0; i < value.size(); ++i) check_plugin_schema(value[i], fmt::format("{}/{}", at, i));
      else
        check_plugin_schema(value, at);
    }
  }
}

// Arrays whose schema asks for unique items are checked here, in n log n, before valijson, which
// is given the schema without them (without_unique_items): it compares every pair, distinct or
// not, and records an error for each pair of duplicates.
void check_unique_items(const json& document, const json& instance, std::vector<std::string>& tokens,
                        const std::string& prefix) {
  if (instance.is_object()) {
    for (const auto& [key, value] : instance.items()) {
      tokens.push_back(key);
      check_unique_items(document, value, tokens, prefix);
      tokens.pop_back();
    }
    return;
  }
  if (!instance.is_array()) return;
  const json* schema = resolve(document, schema_at(document, tokens, tokens.size()));
  const bool unique = schema != nullptr && schema->is_object() && schema->value("uniqueItems", false) == true;
  std::set<json> seen;
  for (std::size_t i = 0; i < instance.size(); ++i) {
    tokens.push_back(std::to_string(i));
    if (unique && !seen.insert(instance[i]).second)
      throw InputError(fmt::format("{}{}: a repeated item ({}); expected items that are all different", prefix,
                                   pointer_of(tokens, tokens.size()), brief(instance[i])));
    check_unique_items(document, instance[i], tokens, prefix);
    tokens.pop_back();
  }
}

// The schema without its uniqueItems keywords (a boolean value: a property of that name has a
// schema as its value). Only the host's own schemas have any (plugin schemas may not), where
// check_unique_items finds them.
json without_unique_items(json node) {
  if (node.is_object()) {
    if (auto it = node.find("uniqueItems"); it != node.end() && it->is_boolean()) node.erase(it);
    for (auto& [key, value] : node.items()) value = without_unique_items(std::move(value));
  } else if (node.is_array()) {
    for (auto& value : node) value = without_unique_items(std::move(value));
  }
  return node;
}

}  // namespace

void check_parameter_schema(const json& schema) { check_plugin_schema(schema, ""); }

std::string brief(const json& value) {
  std::string text = value.dump();
  constexpr std::size_t kMax = 60;
  if (text.size() > kMax) text = text.substr(0, kMax - 3) + "...";
  return text;
}

SchemaValidator::SchemaValidator(json schema) : impl_(std::make_unique<Impl>()) {
  impl_->document = std::move(schema);
  try {
    valijson::SchemaParser parser(valijson::SchemaParser::kDraft7);
    const json checked = without_unique_items(impl_->document);
    valijson::adapters::NlohmannJsonAdapter adapter(checked);
    parser.populateSchema(adapter, impl_->schema);
  } catch (const std::exception& e) {
    throw std::invalid_argument(std::string("not a usable JSON Schema: ") + e.what());
  }
}

SchemaValidator::~SchemaValidator() = default;
SchemaValidator::SchemaValidator(SchemaValidator&&) noexcept = default;

void SchemaValidator::validate(const json& instance, const std::string& prefix) const {
  std::vector<std::string> tokens;
  check_unique_items(impl_->document, instance, tokens, prefix);
  valijson::Validator validator;
  valijson::adapters::NlohmannJsonAdapter adapter(instance);
  if (validator.validate(impl_->schema, adapter, nullptr)) return;  // stops at the first violation
  valijson::ValidationResults results;
  validator.validate(impl_->schema, adapter, &results);
  throw InputError(message(impl_->document, instance, most_specific(results), prefix));
}

}  // namespace varia::host
