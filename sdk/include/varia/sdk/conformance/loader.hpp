// Loading one plugin file for the conformance suites (Boost.DLL), the way the host does: the ABI
// version first, then the metadata, then objects made by its factory. An object holds a reference
// to its library, so the library never unloads under a live object.
#pragma once

#include <boost/dll/shared_library.hpp>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "varia/abi/plugin_object.hpp"
#include "varia/sdk/plugin.hpp"

namespace varia::sdk::conformance {

class LoadedPlugin {
 public:
  // Throws std::runtime_error naming the file when it is not a varia plugin of this ABI version.
  explicit LoadedPlugin(const std::filesystem::path& file) : file_(file) {
    library_ = std::make_shared<boost::dll::shared_library>();
    boost::dll::fs::error_code ec;
    library_->load(file, ec, boost::dll::load_mode::rtld_now | boost::dll::load_mode::rtld_local);
    if (ec) throw std::runtime_error(file.string() + ": cannot be loaded: " + ec.message());
    if (!library_->has("varia_abi_version")) throw std::runtime_error(file.string() + ": no varia_abi_version");
    const int abi = library_->get<const int>("varia_abi_version");
    if (abi != kAbiVersion)
      throw std::runtime_error(file.string() + ": ABI version " + std::to_string(abi) + ", expected " +
                               std::to_string(kAbiVersion));
    if (!library_->has("varia_info") || !library_->has("varia_create"))
      throw std::runtime_error(file.string() + ": no varia_info or varia_create (use VARIA_PLUGIN)");
    info_ = library_->get_alias<InfoFunction>("varia_info")();
  }

  const std::filesystem::path& file() const { return file_; }
  const PluginInfo& info() const { return *info_; }
  nlohmann::json parameter_schema() const { return nlohmann::json::parse(info_->parameter_schema); }

  // An object of the plugin's kind T made from `parameters` in `context`, with the parts it takes
  // (abi/plugin_object.hpp, Part; the caller keeps them alive as long as the object); throws
  // std::runtime_error with the plugin's message when it refuses them (without the factory's
  // kRefusedParameter mark of a refused value).
  template <class T>
  std::shared_ptr<T> create(const nlohmann::json& parameters,
                            const nlohmann::json& context = {{"manifold", "Rn"}, {"point_size", 1}, {"dim", 1}},
                            const std::vector<Part>& parts = {}) const {
    char error[512] = "";
    const std::string parameter_text = parameters.dump(), context_text = context.dump();
    PluginObject* object = nullptr;
    if (parts.empty()) {
      auto& factory = library_->get_alias<CreateFunction>("varia_create");
      object = factory(parameter_text.c_str(), context_text.c_str(), error, sizeof error);
    } else {
      if (!library_->has("varia_create_parts")) throw std::runtime_error(file_.string() + ": no varia_create_parts");
      auto& factory = library_->get_alias<CreateWithPartsFunction>("varia_create_parts");
      object = factory(parameter_text.c_str(), context_text.c_str(), parts.data(), static_cast<int>(parts.size()),
                       error, sizeof error);
    }
    if (object == nullptr) {
      const char* refused = refused_parameter(error);
      throw std::runtime_error(refused != nullptr ? refused : error);
    }
    // Made by the plugin, so typeid and dynamic_cast across the boundary are not to be trusted:
    // the object is T because the plugin's kind says so.
    auto library = library_;
    return std::shared_ptr<T>(static_cast<T*>(object), [library](T* p) { delete p; });
  }

 private:
  std::filesystem::path file_;
  std::shared_ptr<boost::dll::shared_library> library_;
  const PluginInfo* info_ = nullptr;
};

}  // namespace varia::sdk::conformance
