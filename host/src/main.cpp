// The varia program (spec: docs/interface.md, "Commands").
#include "cli.hpp"

int main(int argc, char** argv) { return varia::host::main_cli(argc, argv); }
