// Fault plugin: the right ABI version and a type marker, but no varia_info metadata (the host
// must refuse it, exit code 3 when a scene needs it).
#include <boost/config.hpp>

#include "varia/abi/plugin_object.hpp"

extern "C" BOOST_SYMBOL_EXPORT const int varia_abi_version = varia::kAbiVersion;
extern "C" BOOST_SYMBOL_EXPORT const char varia_type_lagrangian__fault_no_info = 0;
