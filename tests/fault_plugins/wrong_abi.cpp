// Fault plugin: a varia plugin of another ABI version (the host must refuse it before importing
// anything else, exit code 3 when a scene needs it).
#include <boost/config.hpp>

#include "varia/abi/plugin_object.hpp"

extern "C" BOOST_SYMBOL_EXPORT const int varia_abi_version = varia::kAbiVersion + 100;
extern "C" BOOST_SYMBOL_EXPORT const char varia_type_lagrangian__fault_abi = 0;
