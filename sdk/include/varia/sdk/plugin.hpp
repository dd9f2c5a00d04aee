// Writing a plugin: derive from a kind's interface (core/include/varia/core/*.hpp), give the class
// a constructor Class(const nlohmann::json& parameters, const varia::sdk::Context& context) and
// the static members `version`, `parameter_schema` (JSON Schema, draft-07) and `properties`
// (JSON: what the host shows and the theorems use), then export it with
//
//   VARIA_PLUGIN(Class, kind, type)
//
// where kind is one of manifold, quadrature, lagrangian, one_step, effect, force, constraint and type is the
// type name with '-' written as '_' (VARIA_PLUGIN(Pendulum, lagrangian, pendulum);
// VARIA_PLUGIN(GaussLegendre, quadrature, gauss_legendre) is type "gauss-legendre").
//
// The macro exports, through Boost.DLL:
//   varia_abi_version          int, read by the host before anything else;
//   varia_type_<kind>__<type>  a marker the host finds in the symbol table without loading the
//                              file, so that a run loads only the files its scene names;
//   varia_info                 the metadata, read without constructing anything;
//   varia_create               the factory; it converts every exception into a message;
//   varia_create_parts         the same factory, given the parts the host made from the
//                              parameters the schema marks "x-varia-part" (Context::parts_of).
#pragma once

#include <boost/config.hpp>
#include <boost/dll/alias.hpp>
#include <cstring>
#include <exception>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "varia/abi/plugin_object.hpp"

namespace varia::sdk {

// What the host tells a plugin about the rest of the scene when it constructs it.
struct Context {
  // The manifold's type name, e.g. "Rn", "SO3"; a manifold made of parts is named with its parts,
  // "product(SO3,SO3)".
  std::string manifold;
  int point_size = 0;  // numbers per configuration point
  int dim = 0;         // tangent dimension
  // The parts the host made for this object (abi/plugin_object.hpp, Part), borrowed: the host keeps
  // them alive as long as the object.
  std::vector<Part> parts{};

  // The parts of one role, which the schema declares of kind `kind`; each is checked to be of it.
  template <class K>
  std::vector<K*> parts_of(std::string_view role, Kind kind) const {
    std::vector<K*> found;
    for (const Part& part : parts) {
      if (role != part.role) continue;
      if (part.object == nullptr || part.object->kind() != kind)
        throw std::runtime_error("the part '" + std::string(role) + "' the host passed is not of the declared kind");
      found.push_back(static_cast<K*>(part.object));
    }
    return found;
  }
};

struct PluginInfo {
  const char* kind;
  const char* type;
  const char* version;
  const char* parameter_schema;
  const char* properties;
};

using CreateFunction = PluginObject*(const char* parameters, const char* context, char* error,
                                     int error_size) noexcept;
using CreateWithPartsFunction = PluginObject*(const char* parameters, const char* context, const Part* parts,
                                              int part_count, char* error, int error_size) noexcept;
using InfoFunction = const PluginInfo*() noexcept;

// Runs f, turning any exception into the Status message kept in `store` (the boundary rule).
template <class F>
Status guarded(std::string& store, F&& f) noexcept {
  try {
    f();
    return nullptr;
  } catch (const std::exception& e) {
    store = e.what();
  } catch (...) {
    store = "unknown exception";
  }
  return store.c_str();
}

// Copies a message into a caller-owned buffer, truncating safely.
inline void copy_message(const std::string& message, char* out, int size) noexcept {
  if (out == nullptr || size <= 0) return;
  std::strncpy(out, message.c_str(), static_cast<std::size_t>(size - 1));
  out[size - 1] = '\0';
}

inline Context parse_context(const char* text) {
  const auto j = nlohmann::json::parse(text);
  Context context;
  context.manifold = j.value("manifold", "");
  context.point_size = j.value("point_size", 0);
  context.dim = j.value("dim", 0);
  return context;
}

template <class Class>
PluginObject* create_with_parts(const char* parameters, const char* context, const Part* parts, int part_count,
                                char* error, int error_size) noexcept {
  std::string message;
  try {
    Context parsed = parse_context(context);
    parsed.parts.assign(parts, parts + (parts != nullptr && part_count > 0 ? part_count : 0));
    return new Class(nlohmann::json::parse(parameters), parsed);
  } catch (const std::invalid_argument& e) {  // a parameter value the plugin refuses: bad input
    message = std::string(kRefusedParameter) + e.what();
  } catch (const std::exception& e) {
    message = e.what();
  } catch (...) {
    message = "unknown exception";
  }
  copy_message(message, error, error_size);
  return nullptr;
}

template <class Class>
PluginObject* create(const char* parameters, const char* context, char* error, int error_size) noexcept {
  return create_with_parts<Class>(parameters, context, nullptr, 0, error, error_size);
}

}  // namespace varia::sdk

#define VARIA_PLUGIN_STR2(x) #x
#define VARIA_PLUGIN_STR(x) VARIA_PLUGIN_STR2(x)

#define VARIA_PLUGIN(Class, kind_ident, type_ident)                                          \
  extern "C" BOOST_SYMBOL_EXPORT const int varia_abi_version = ::varia::kAbiVersion;         \
  extern "C" BOOST_SYMBOL_EXPORT const char varia_type_##kind_ident##__##type_ident = 0;     \
  namespace {                                                                                \
  const ::varia::sdk::PluginInfo* varia_plugin_info() noexcept {                            \
    static const std::string type = [] {                                                     \
      std::string t = VARIA_PLUGIN_STR(type_ident);                                          \
      for (char& c : t)                                                                      \
        if (c == '_') c = '-';                                                               \
      return t;                                                                              \
    }();                                                                                     \
    static const ::varia::sdk::PluginInfo info{VARIA_PLUGIN_STR(kind_ident), type.c_str(),   \
                                               Class::version, Class::parameter_schema,      \
                                               Class::properties};                           \
    return &info;                                                                            \
  }                                                                                          \
  ::varia::PluginObject* varia_plugin_create(const char* p, const char* c, char* e,         \
                                             int n) noexcept {                               \
    return ::varia::sdk::create<Class>(p, c, e, n);                                          \
  }                                                                                          \
  ::varia::PluginObject* varia_plugin_create_parts(const char* p, const char* c,            \
                                                   const ::varia::Part* parts, int count,   \
                                                   char* e, int n) noexcept {               \
    return ::varia::sdk::create_with_parts<Class>(p, c, parts, count, e, n);                 \
  }                                                                                          \
  }                                                                                          \
  BOOST_DLL_ALIAS(varia_plugin_info, varia_info)                                             \
  BOOST_DLL_ALIAS(varia_plugin_create, varia_create)                                         \
  BOOST_DLL_ALIAS(varia_plugin_create_parts, varia_create_parts)
