// A test-local plugin loader (Boost.DLL), so that the plugin tests load the real .so files the
// build writes to ${VARIA_BUILD_DIR}/lib/varia/plugins. An object made by a plugin holds a
// reference to its library, so the library never unloads under a live object.
#pragma once

#include <algorithm>
#include <boost/dll/shared_library.hpp>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "varia/core/plugin_object.hpp"
#include "varia/sdk/plugin.hpp"

namespace varia::test {

inline std::filesystem::path plugin_directory() {
  return std::filesystem::path(VARIA_BUILD_DIR) / "lib" / "varia" / "plugins";
}

// The plugin files <kind>_*.so of the build, sorted by name.
inline std::vector<std::filesystem::path> plugin_files(const std::string& kind) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(plugin_directory())) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kind + "_", 0) == 0 && entry.path().extension() == ".so")
      files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

class LoadedPlugin {
 public:
  // Loads `file` and checks its ABI version before importing anything else.
  explicit LoadedPlugin(const std::filesystem::path& file)
      : file_(file), library_(std::make_shared<boost::dll::shared_library>(file)) {
    const int abi = library_->get<const int>("varia_abi_version");
    if (abi != kAbiVersion)
      throw std::runtime_error(file.string() + ": ABI version " + std::to_string(abi) +
                               ", expected " + std::to_string(kAbiVersion));
    info_ = library_->get_alias<sdk::InfoFunction>("varia_info")();
  }

  const std::filesystem::path& file() const { return file_; }
  const sdk::PluginInfo& info() const { return *info_; }
  nlohmann::json parameter_schema() const { return nlohmann::json::parse(info_->parameter_schema); }

  // An object of the plugin's kind T made from `parameters`; throws std::runtime_error with the
  // plugin's message when it refuses them.
  template <class T>
  std::shared_ptr<T> create(const nlohmann::json& parameters,
                            const nlohmann::json& context = {
                                {"manifold", "Rn"}, {"point_size", 1}, {"dim", 1}}) const {
    char error[512] = "";
    auto& factory = library_->get_alias<sdk::CreateFunction>("varia_create");
    PluginObject* object =
        factory(parameters.dump().c_str(), context.dump().c_str(), error, sizeof error);
    if (object == nullptr) throw std::runtime_error(error);
    // Made by the plugin, so typeid and dynamic_cast across the boundary are not to be trusted:
    // the object is T because the plugin's kind says so.
    auto library = library_;
    return std::shared_ptr<T>(static_cast<T*>(object), [library](T* p) { delete p; });
  }

 private:
  std::filesystem::path file_;
  std::shared_ptr<boost::dll::shared_library> library_;
  const sdk::PluginInfo* info_ = nullptr;
};

// The plugin <kind>_<type>.so of the build (type with '-' written '_').
inline LoadedPlugin load_plugin(const std::string& kind, const std::string& type) {
  return LoadedPlugin(plugin_directory() / (kind + "_" + type + ".so"));
}

}  // namespace varia::test
