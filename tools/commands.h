// The sdfstream subcommands. Each parses its own arguments, prints --help, and returns the exit
// code; errors surface as exceptions that main() turns into one line on stderr. The work itself
// lives in the modules (world/, demo/, bench/); these only turn flags into their options.
#pragma once

namespace sdfstream::cli {

int runImport(int argc, char** argv);         // tools/cmd_import.cpp
int runRender(int argc, char** argv);         // tools/cmd_render.cpp
int runInfo(int argc, char** argv);           // tools/cmd_pack.cpp
int runVerify(int argc, char** argv);         // tools/cmd_pack.cpp
int runMerge(int argc, char** argv);          // tools/cmd_pack.cpp
int runDemo(int argc, char** argv);           // tools/cmd_demo.cpp
int runFly(int argc, char** argv);            // tools/cmd_fly.cpp
int runView(int argc, char** argv);           // tools/cmd_view.cpp
int runGenerateWorld(int argc, char** argv);  // tools/cmd_generate_world.cpp
int runBench(int argc, char** argv);          // tools/cmd_bench.cpp
int runBenchScroll(int argc, char** argv);    // tools/cmd_bench_stream.cpp (argv[2] == "scroll")
int runBenchStream(int argc, char** argv);    // tools/cmd_bench_stream.cpp (argv[2] == "stream")
int runBenchGi(int argc, char** argv);        // tools/cmd_bench_gi.cpp (argv[2] == "gi")
int runStress(int argc, char** argv);         // tools/cmd_stress.cpp
int runBenchHost(int argc, char** argv);      // tools/cmd_stress.cpp (argv[2] == "host")

}  // namespace sdfstream::cli
