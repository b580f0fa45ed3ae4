// orchestrate: entry point.
#include <iostream>

#include "cli.h"
#include "engine/runner.h"

int main(int argc, char** argv) {
  mill::engine::install_signal_forwarding();
  return mill::cli_main(argc, argv, std::cout, std::cerr);
}
