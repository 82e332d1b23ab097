// The sdfstream subcommands. Each parses its own arguments, prints --help, and returns the exit
// code; errors surface as exceptions that main() turns into one line on stderr.
#pragma once

namespace sdfstream::cli {

int runImport(int argc, char** argv);
int runRender(int argc, char** argv);
int runInfo(int argc, char** argv);
int runDemo(int argc, char** argv);

}  // namespace sdfstream::cli
