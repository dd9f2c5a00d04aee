// The varia program (spec: /work/shared/spec/interface.md, "Commands").
#include "cli.hpp"

int main(int argc, char** argv) { return varia::host::main_cli(argc, argv); }
