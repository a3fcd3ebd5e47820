// kushner: banks of nonlinear stochastic systems and filters. Command-line entry point.
#include "drivers/command_line.hpp"

int main(int argc, char** argv) { return kushner::command_line_main(argc, argv); }
