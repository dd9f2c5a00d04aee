// A shared library that is not a varia plugin at all: no varia_abi_version, no marker.
extern "C" __attribute__((visibility("default"))) int foreign_function() { return 42; }
