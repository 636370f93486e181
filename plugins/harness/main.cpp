// deformkit: the standalone host. Exit codes: 0 success; 2 bad input or usage, with one line on stderr;
// 1 storage that failed while writing (StorageError, standard output), out of memory, internal error.
#include "cli.h"

int main(int argc, char** argv) {
    deformkit::harness::CommandLine cli;
    deformkit::harness::addCommands(cli);
    return cli.run(argc, argv);
}
