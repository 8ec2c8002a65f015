// steadyxr: the command-line tool (see cli.h and `steadyxr --help`).
#include "cli.h"

#include <iostream>

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  return steadyxr::cli::run(args, steadyxr::layer::processEnvironment(), std::cout, std::cerr);
}
