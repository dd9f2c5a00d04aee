#include "registry.hpp"

#include <dlfcn.h>
#include <elf.h>
#include <sys/stat.h>
#include <unistd.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <fstream>
#include <optional>
#include <cerrno>
#include <cstring>
#include <cstdlib>
#include <cctype>
#include <set>
#include <string_view>
#include <vector>  // boost/dll/library_info.hpp (Boost 1.74) uses std::vector without including it

#include <boost/dll/library_info.hpp>
#include <boost/dll/runtime_symbol_info.hpp>
#include <boost/dll/shared_library.hpp>

#include "crash.hpp"
#include "json_reader.hpp"
#include "json_schema.hpp"
#include "output.hpp"
#include "plugin_trust.hpp"

namespace fs = std::filesystem;

namespace varia::host {

namespace {

constexpr std::string_view kMarkerPrefix = "varia_type_";

// A candidate refused while loading; the registry adds the file name.
struct Refused {
  std::string reason;
};

constexpr Kind kKinds[] = {Kind::manifold, Kind::quadrature, Kind::lagrangian, Kind::one_step,
                           Kind::effect,   Kind::force,      Kind::constraint};

std::string kind_name(Kind kind) {
  switch (kind) {
    case Kind::manifold: return "manifold";
    case Kind::quadrature: return "quadrature";
    case Kind::lagrangian: return "lagrangian";
    case Kind::one_step: return "one_step";
    case Kind::effect: return "effect";
    case Kind::force: return "force";
    case Kind::constraint: return "constraint";
  }
  return "unknown";
}

// "varia_type_<kind>__<type>" with '-' written as '_' in <type> (sdk/plugin.hpp).
std::optional<Marker> parse_marker(std::string_view symbol) {
  if (symbol.substr(0, kMarkerPrefix.size()) != kMarkerPrefix) return std::nullopt;
  symbol.remove_prefix(kMarkerPrefix.size());
  const auto split = symbol.find("__");
  if (split == std::string_view::npos || split == 0 || split + 2 == symbol.size()) return std::nullopt;
  Marker marker{std::string(symbol.substr(0, split)), std::string(symbol.substr(split + 2))};
  std::replace(marker.type.begin(), marker.type.end(), '_', '-');
  return marker;
}

// Each directory's *.so regular files, sorted; a missing directory contributes nothing.
std::vector<fs::path> so_files(const fs::path& directory) {
  std::vector<fs::path> files;
  std::error_code ec;
  if (!fs::is_directory(directory, ec)) return files;
  for (fs::directory_iterator it(directory, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code type_ec;
    if (it->path().extension() == ".so" && it->is_regular_file(type_ec)) files.push_back(it->path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// dlopen's own reason for refusing a file, asked again as open_library asked (Boost.DLL keeps only
// a generic error code).
std::string dlopen_error(const fs::path& file) {
  void* handle = ::dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle != nullptr) {
    ::dlclose(handle);
    return "cannot be loaded";
  }
  const char* error = ::dlerror();
  return error != nullptr ? error : "cannot be loaded";
}

// Metadata is read as a scene is (json_reader.hpp): bounded in size and nesting (every walk of a
// schema recurses, and a schema nested 200,000 deep overflowed the stack), without repeated keys.
nlohmann::json parse_metadata(const char* text, const char* what) {
  try {
    return parse_json_text(text);
  } catch (const InputError& e) {
    throw Refused{fmt::format("malformed {} in varia_info: {}", what, e.what())};
  }
}

// The parameter schema, refused when the host would not give it to valijson or valijson cannot
// read it: a bad schema refuses its plugin only (docs/security.md, "Plugins").
nlohmann::json parameter_schema(const char* text) {
  nlohmann::json schema = parse_metadata(text, "parameter_schema");
  try {
    check_parameter_schema(schema);
    SchemaValidator{schema};
  } catch (const std::invalid_argument& e) {
    throw Refused{fmt::format("unusable parameter_schema in varia_info: {}", e.what())};
  }
  return schema;
}

// Deletes a plugin's object, then the parts it borrowed, then releases the object's hold on the
// library that made it.
struct PluginDeleter {
  std::shared_ptr<boost::dll::shared_library> library;
  std::vector<MadePart> parts;
  void operator()(PluginObject* object) {
    delete object;
    parts.clear();
    library.reset();
  }
};

}  // namespace

struct Registry::Loaded {
  std::shared_ptr<boost::dll::shared_library> library;
  sdk::CreateFunction* create = nullptr;
  sdk::CreateWithPartsFunction* create_with_parts = nullptr;  // null for a plugin without part roles
  PluginRecord record;
};

namespace {

// Opens the file at its canonical path, the one whose directories distrust() checked: a link on
// the path as given is not followed again. Every symbol is resolved now (RTLD_NOW): a file that
// needs one no library defines is refused here, with the linker's reason, rather than ending the
// process at its first call.
std::shared_ptr<boost::dll::shared_library> open_library(const fs::path& file) {
  auto library = std::make_shared<boost::dll::shared_library>();
  boost::dll::fs::error_code ec;
  std::error_code canonical_ec;
  const fs::path real = fs::canonical(file, canonical_ec);
  if (canonical_ec) throw Refused{"cannot be opened: " + canonical_ec.message()};
  library->load(real, ec, boost::dll::load_mode::rtld_now | boost::dll::load_mode::rtld_local);
  if (ec) throw Refused{"not a loadable shared library: " + dlopen_error(file)};
  return library;
}

// The typed properties of the metadata's "properties" object; a plugin declaring one with the
// wrong type is refused.
DeclaredProperties declared_properties(const nlohmann::json& properties) {
  DeclaredProperties declared;
  if (const auto it = properties.find("symplectic"); properties.is_object() && it != properties.end()) {
    if (!it->is_boolean())
      throw Refused{fmt::format("its properties declare \"symplectic\": {}, expected true or false", it->dump())};
    declared.symplectic = it->get<bool>();
  }
  return declared;
}

// The ABI check comes before anything else is imported (Boost.DLL, doc/missuses.qbk).
void check_abi(const boost::dll::shared_library& library) {
  if (!library.has("varia_abi_version"))
    throw Refused{"not a varia plugin (no varia_abi_version symbol)"};
  const int version = library.get<const int>("varia_abi_version");
  if (version != kAbiVersion)
    throw Refused{fmt::format("ABI version {}, this host speaks {}", version, kAbiVersion)};
}

// The parameters a plugin's schema marks "x-varia-part": "<kind>", its part roles.
std::vector<PartRole> part_roles(const nlohmann::json& schema) {
  std::vector<PartRole> roles;
  const auto properties = schema.find("properties");
  if (properties == schema.end() || !properties->is_object()) return roles;
  for (const auto& [name, property] : properties->items()) {
    const auto mark = property.is_object() ? property.find("x-varia-part") : property.end();
    if (!property.is_object() || mark == property.end()) continue;
    const bool known = mark->is_string() && std::any_of(std::begin(kKinds), std::end(kKinds), [&](Kind k) {
      return kind_name(k) == mark->get<std::string>();
    });
    if (!known)
      throw Refused{fmt::format("its parameter_schema marks '{}' as parts of kind {}, which is not a plugin kind",
                                name, mark->dump())};
    roles.push_back(PartRole{name, mark->get<std::string>()});
  }
  return roles;
}

PluginRecord read_info(const boost::dll::shared_library& library, const fs::path& file) {
  if (!library.has("varia_info")) throw Refused{"missing metadata (no varia_info)"};
  const sdk::PluginInfo* info = library.get_alias<sdk::InfoFunction>("varia_info")();
  if (info == nullptr || info->kind == nullptr || info->type == nullptr ||
      info->version == nullptr || info->parameter_schema == nullptr || info->properties == nullptr)
    throw Refused{"missing metadata (varia_info has an empty field)"};
  PluginRecord record{file, info->kind, info->type, info->version, parameter_schema(info->parameter_schema),
                      parse_metadata(info->properties, "properties"), {}, {}};
  record.declared = declared_properties(record.properties);
  record.part_roles = part_roles(record.parameter_schema);
  return record;
}

}  // namespace

std::shared_ptr<Registry::Loaded> Registry::load(const fs::path& file, const SymbolScan& scan) {
  try {
    if (!scan.parsed) throw Refused{"not a shared library (its format cannot be read)"};
    // Its type is read from the exported markers without running it; a file whose symbols cannot
    // be read (no section headers) would have to run its code to tell, so it is not loaded at all.
    if (!scan.has_symbol_table)
      throw Refused{"its dynamic symbol table cannot be read (no section headers), so its type cannot be read "
                    "without running its code, and it is not loaded"};
    auto loaded = std::make_shared<Loaded>();
    note_plugin_file(file);  // before its code runs: a crash in its initializers is named too
    loaded->library = open_library(file);
    check_abi(*loaded->library);
    loaded->record = read_info(*loaded->library, file);
    const auto& record = loaded->record;
    const bool declared = std::any_of(scan.markers.begin(), scan.markers.end(), [&](const Marker& m) {
      return m.kind == record.kind && m.type == record.type;
    });
    if (!declared)
      throw Refused{fmt::format("varia_info says {} '{}' but no matching varia_type_ marker is exported",
                                record.kind, record.type)};
    if (!loaded->library->has("varia_create")) throw Refused{"no varia_create factory"};
    loaded->create = &loaded->library->get_alias<sdk::CreateFunction>("varia_create");
    if (!record.part_roles.empty()) {
      if (!loaded->library->has("varia_create_parts"))
        throw Refused{fmt::format("its parameter_schema declares parts ('{}') but it exports no varia_create_parts "
                                  "factory to take them",
                                  record.part_roles.front().role)};
      loaded->create_with_parts = &loaded->library->get_alias<sdk::CreateWithPartsFunction>("varia_create_parts");
    }
    return loaded;
  } catch (const Refused& refused) {
    throw PluginLoadError(fmt::format("{}: {}", file.string(), refused.reason));
  } catch (const std::exception& e) {  // boost::dll reading a symbol
    throw PluginLoadError(fmt::format("{}: {}", file.string(), e.what()));
  }
}

std::vector<fs::path> Registry::search_path(const std::vector<std::string>& plugin_paths) {
  return search_path(plugin_paths, boost::dll::program_location().parent_path() / ".." / "lib" / "varia" / "plugins");
}

std::vector<fs::path> Registry::search_path(const std::vector<std::string>& plugin_paths, const fs::path& bundled) {
  // Spec "Build layout": bundled plugins, then --plugin-path, then VARIA_PLUGIN_PATH.
  std::vector<fs::path> directories{bundled.lexically_normal()};
  for (const auto& path : plugin_paths) directories.emplace_back(path);
  for (fs::path& path : path_list("VARIA_PLUGIN_PATH")) directories.push_back(std::move(path));
  return directories;
}

Registry::Registry(std::vector<fs::path> directories) : directories_(std::move(directories)) {}
Registry::~Registry() = default;

const std::vector<fs::path>& Registry::candidates() {
  if (candidates_) return *candidates_;
  const std::vector<fs::path> trusted = trusted_directories();
  candidates_.emplace();
  std::set<fs::path> seen;  // a directory named twice must not make its plugins duplicates
  for (const auto& directory : directories_) {
    const auto files = so_files(directory);
    for (const auto& file : files) {
      std::error_code ec;
      const auto canonical = fs::weakly_canonical(file, ec);
      if (!seen.insert(ec ? file : canonical).second) continue;
      const std::string reason = distrust(file, trusted);
      if (reason.empty())
        candidates_->push_back(file);
      else
        untrusted_.push_back(Refusal{file, "not trusted: " + reason});
    }
  }
  return *candidates_;
}

namespace {

// The names in the dynamic symbol table (.dynsym) of an ELF64 file of this machine's byte order:
// what the dynamic loader reads, so `strip` keeps it (boost::dll::library_info reads .symtab only).
// None when the file is not such a file.
std::optional<std::vector<std::string>> dynamic_symbols(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  Elf64_Ehdr header{};
  constexpr unsigned char kByteOrder = std::endian::native == std::endian::little ? ELFDATA2LSB : ELFDATA2MSB;
  if (!in.read(reinterpret_cast<char*>(&header), sizeof header) || std::memcmp(header.e_ident, ELFMAG, SELFMAG) != 0 ||
      header.e_ident[EI_CLASS] != ELFCLASS64 || header.e_ident[EI_DATA] != kByteOrder ||
      header.e_shentsize != sizeof(Elf64_Shdr))
    return std::nullopt;
  std::vector<Elf64_Shdr> sections(header.e_shnum);
  in.seekg(static_cast<std::streamoff>(header.e_shoff));
  if (!in.read(reinterpret_cast<char*>(sections.data()), static_cast<std::streamsize>(sections.size() * sizeof(Elf64_Shdr))))
    return std::nullopt;
  const auto contents = [&](const Elf64_Shdr& section) -> std::optional<std::string> {
    constexpr std::uint64_t kMaxBytes = 64u << 20;
    if (section.sh_size > kMaxBytes) return std::nullopt;
    std::string bytes(section.sh_size, '\0');
    in.seekg(static_cast<std::streamoff>(section.sh_offset));
    if (!in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()))) return std::nullopt;
    return bytes;
  };
  std::vector<std::string> names;
  for (const auto& section : sections) {
    if (section.sh_type != SHT_DYNSYM || section.sh_link >= sections.size() || section.sh_entsize != sizeof(Elf64_Sym))
      continue;
    const auto table = contents(section), strings = contents(sections[section.sh_link]);
    if (!table || !strings) return std::nullopt;
    for (std::size_t at = 0; at + sizeof(Elf64_Sym) <= table->size(); at += sizeof(Elf64_Sym)) {
      Elf64_Sym symbol{};
      std::memcpy(&symbol, table->data() + at, sizeof symbol);
      if (symbol.st_name < strings->size())
        names.emplace_back(strings->data() + symbol.st_name, strnlen(strings->data() + symbol.st_name,
                                                                      strings->size() - symbol.st_name));
    }
  }
  return names;
}

}  // namespace

const SymbolScan& Registry::scan(const fs::path& file) {
  auto [it, inserted] = scans_.try_emplace(file);
  if (!inserted) return it->second;
  SymbolScan& result = it->second;
  const auto read = [&](const auto& symbols) {
    result.parsed = true;
    result.has_symbol_table = !symbols.empty();
    for (const auto& symbol : symbols)
      if (auto marker = parse_marker(symbol)) result.markers.push_back(std::move(*marker));
  };
  if (const auto names = dynamic_symbols(file)) {
    read(*names);
    return result;
  }
  try {  // not ELF64: what boost::dll can read
    boost::dll::library_info info(file, false);
    read(info.symbols());
  } catch (const std::exception&) {
    result.parsed = false;  // reported by list(); find() skips it
  }
  return result;
}

std::vector<fs::path> Registry::files_declaring(const std::string& kind, const std::string& type) {
  std::vector<fs::path> files;
  for (const auto& file : candidates()) {
    const SymbolScan& s = scan(file);
    const bool declares = std::any_of(s.markers.begin(), s.markers.end(), [&](const Marker& m) {
      return m.kind == kind && m.type == type;
    });
    if (declares) files.push_back(file);
  }
  return files;
}

std::string Registry::valid_types(const std::string& kind) {
  std::set<std::string> types;
  for (const auto& file : candidates())
    for (const auto& marker : scan(file).markers)
      if (marker.kind == kind) types.insert(marker.type);
  if (types.empty()) {
    std::vector<std::string> directories;
    for (const auto& d : directories_) directories.push_back(d.string());
    return fmt::format("no {} plugins were found in: {}", kind, fmt::join(directories, ", "));
  }
  return fmt::format("valid {} types are: {}", kind, fmt::join(types, ", "));
}

void Registry::check_not_refused(const std::string& kind, const std::string& type) {
  for (const auto& refusal : untrusted_) {
    const auto& markers = scan(refusal.file).markers;
    const bool declares = std::any_of(markers.begin(), markers.end(), [&](const Marker& m) {
      return m.kind == kind && m.type == type;
    });
    if (declares)
      throw PluginLoadError(fmt::format("{}: {} type '{}' is in this file, which was refused: {}",
                                        refusal.file.string(), kind, type, refusal.reason));
  }
}

const PluginRecord& Registry::find(const std::string& kind, const std::string& type) {
  const std::string key = kind + "/" + type;
  if (const auto it = loaded_.find(key); it != loaded_.end()) return it->second->record;
  const auto files = files_declaring(kind, type);
  if (files.empty()) check_not_refused(kind, type);
  // The name as the scene gave it, shown printable: a NUL in it would end the message there.
  if (files.empty())
    throw InputError(fmt::format("unknown {} type '{}'; {}", kind, printable(type), valid_types(kind)));
  if (files.size() > 1)
    throw PluginLoadError(fmt::format("{} type '{}' is provided by two files: {} and {}", kind, type,
                                      files[0].string(), files[1].string()));
  auto loaded = load(files[0], scan(files[0]));
  const PluginRecord& record = loaded->record;
  if (record.kind != kind || record.type != type)
    throw PluginLoadError(fmt::format("{}: declares {} '{}' in varia_info, not {} '{}'",
                                      files[0].string(), record.kind, record.type, kind, type));
  load_order_.push_back(type);
  return loaded_.emplace(key, std::move(loaded)).first->second->record;
}

// The part a plugin's failure names first ("terms/2: ..."), whose plugin is then at fault.
std::optional<std::reference_wrapper<const PluginRecord>> Registry::part_named(const std::vector<MadePart>& parts,
                                                                               std::string_view message) {
  const std::size_t slash = message.find('/'), colon = message.find(": ");
  if (slash == std::string_view::npos || colon == std::string_view::npos || slash > colon) return std::nullopt;
  const std::string_view role = message.substr(0, slash), index = message.substr(slash + 1, colon - slash - 1);
  if (index.empty() || index.size() > 9 ||
      !std::all_of(index.begin(), index.end(), [](char c) { return std::isdigit(c) != 0; }))
    return std::nullopt;
  std::size_t wanted = std::stoul(std::string(index)), seen = 0;
  for (const MadePart& part : parts)
    if (part.role == role && seen++ == wanted && part.object->origin() != nullptr)
      return std::cref(record_of(part.object->origin()));
  return std::nullopt;
}

std::shared_ptr<PluginObject> Registry::create(const std::string& kind, const std::string& type,
                                               const nlohmann::json& parameters,
                                               const sdk::Context& context, std::vector<MadePart> parts) {
  const PluginRecord& record = find(kind, type);
  const Loaded& loaded = *loaded_.at(kind + "/" + type);
  const std::string parameter_text = parameters.dump();
  const std::string context_text =
      nlohmann::json{{"manifold", context.manifold}, {"point_size", context.point_size}, {"dim", context.dim}}
          .dump();
  char error[1024] = {};
  std::vector<Part> borrowed;
  for (const MadePart& part : parts) borrowed.push_back(Part{part.role.c_str(), part.object.get()});
  PluginObject* object =
      loaded.create_with_parts != nullptr
          ? loaded.create_with_parts(parameter_text.c_str(), context_text.c_str(), borrowed.data(),
                                     static_cast<int>(borrowed.size()), error, sizeof error)
          : loaded.create(parameter_text.c_str(), context_text.c_str(), error, sizeof error);
  if (object == nullptr) {
    if (const char* refused = refused_parameter(error))
      throw InputError(fmt::format("{} (the {} plugin {})", refused, type, record.file.filename().string()));
    const PluginRecord& at_fault = part_named(parts, error).value_or(record);
    throw PluginLoadError(fmt::format("{}: {}: {}", at_fault.file.string(), at_fault.type,
                                      error[0] != '\0' ? error : "the plugin made no object"));
  }
  std::shared_ptr<PluginObject> owned(object, PluginDeleter{loaded.library, std::move(parts)});
  owned->set_origin(&record);
  if (kind_name(owned->kind()) != kind)
    throw PluginLoadError(fmt::format("{}: {}: made an object of kind {}, not {}", record.file.string(),
                                      type, kind_name(owned->kind()), kind));
  return owned;
}

std::vector<PluginRecord> Registry::list(std::vector<Refusal>& refused) {
  std::vector<PluginRecord> records;
  const auto& files = candidates();
  refused.insert(refused.end(), untrusted_.begin(), untrusted_.end());
  for (const auto& file : files) {
    try {
      records.push_back(load(file, scan(file))->record);
    } catch (const PluginLoadError& e) {
      // The message is "<file>: <reason>"; a Refusal keeps them apart.
      refused.push_back(Refusal{file, std::string(e.what()).substr(file.string().size() + 2)});
    }
  }
  return records;
}

std::vector<std::string> Registry::loaded() const { return load_order_; }

std::string describe(const PluginRecord& record) {
  return fmt::format("{} '{}' ({})", record.kind, record.type, record.file.string());
}

const PluginRecord& Registry::record_of(const void* origin) { return *static_cast<const PluginRecord*>(origin); }

}  // namespace varia::host
