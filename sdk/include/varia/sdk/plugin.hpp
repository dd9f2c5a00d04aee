// Writing a plugin: derive from a kind's interface (core/include/varia/core/*.hpp), give the class
// a constructor Class(const nlohmann::json& parameters, const varia::sdk::Context& context) and
// the static members `version`, `parameter_schema` (JSON Schema, draft-07) and `properties`
// (JSON: what the host shows and the theorems use), then export it with
//
//   VARIA_PLUGIN(Class, kind, type)
//
// where kind is one of manifold, quadrature, lagrangian, one_step, effect, force and type is the
// type name with '-' written as '_' (VARIA_PLUGIN(Pendulum, lagrangian, pendulum);
// VARIA_PLUGIN(GaussLegendre, quadrature, gauss_legendre) is type "gauss-legendre").
//
// The macro exports, through Boost.DLL:
//   varia_abi_version          int, read by the host before anything else;
//   varia_type_<kind>__<type>  a marker the host finds in the symbol table without loading the
//                              file, so that a run loads only the files its scene names;
//   varia_info                 the metadata, read without constructing anything;
//   varia_create               the factory; it converts every exception into a message.
#pragma once

#include <boost/config.hpp>
#include <boost/dll/alias.hpp>
#include <cstring>
#include <exception>
#include <nlohmann/json.hpp>
#include <string>

#include "varia/abi/plugin_object.hpp"

namespace varia::sdk {

// What the host tells a plugin about the rest of the scene when it constructs it.
struct Context {
  std::string manifold;  // manifold type name, e.g. "Rn", "SO3"
  int point_size = 0;    // numbers per configuration point
  int dim = 0;           // tangent dimension
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
  return Context{j.value("manifold", ""), j.value("point_size", 0), j.value("dim", 0)};
}

template <class Class>
PluginObject* create(const char* parameters, const char* context, char* error,
                     int error_size) noexcept {
  std::string message;
  try {
    return new Class(nlohmann::json::parse(parameters), parse_context(context));
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
  }                                                                                          \
  BOOST_DLL_ALIAS(varia_plugin_info, varia_info)                                             \
  BOOST_DLL_ALIAS(varia_plugin_create, varia_create)
