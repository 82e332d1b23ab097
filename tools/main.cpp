// sdfstream: import level data into SDF brick worlds, render them, run the demo.
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include "core/error.h"
#include "tools/commands.h"

namespace {
const char* kUsage =
    "usage: sdfstream <command> [options]   (sdfstream <command> --help for details)\n"
    "\n"
    "commands:\n"
    "  import SCENE.gltf|SCENE.glb|LEVEL.vdb|LAYOUT.json -o WORLD [--voxel SIZE]\n"
    "                 convert level data into a world directory of 8^3 SDF bricks\n"
    "  render WORLD [--camera px,py,pz,tx,ty,tz[,fov]] -o IMAGE.png\n"
    "                 sphere-trace the world on the GPU (lavapipe when no GPU) into a PNG\n"
    "  info WORLD     print a world pack's summary\n"
    "  verify WORLD   check every checksum; name the first bad tile\n"
    "  merge SHARD... -o WORLD   join packs imported with --shard i/n\n"
    "  generate-world -o LAYOUT.json   write the large built-in world's layout\n"
    "  bench import|...   benchmarks (outputs under out/bench)\n"
    "  fly WORLD -o DIR [--path FILE] [--frames N]   stream a fly-through; frames + metrics\n"
    "  view WORLD [--script FILE]   fly in a window (WASD, mouse); streaming and GI live\n"
    "  stress WORLD [--objects 0,10,100,1000,10000]   moving-object stress benchmark: GPU time\n"
    "                 vs object count, regions vs naive vs static-only (outputs under out/stress)\n"
    "  demo [-o DIR]  import the built-in scene, render views, write PNGs and a report\n";
}

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    std::fputs(kUsage, argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  std::string command = argv[1];
  try {
    if (command == "import") return sdfstream::cli::runImport(argc, argv);
    if (command == "render") return sdfstream::cli::runRender(argc, argv);
    if (command == "info") return sdfstream::cli::runInfo(argc, argv);
    if (command == "verify") return sdfstream::cli::runVerify(argc, argv);
    if (command == "merge") return sdfstream::cli::runMerge(argc, argv);
    if (command == "demo") return sdfstream::cli::runDemo(argc, argv);
    if (command == "fly") return sdfstream::cli::runFly(argc, argv);
    if (command == "view") return sdfstream::cli::runView(argc, argv);
    if (command == "generate-world") return sdfstream::cli::runGenerateWorld(argc, argv);
    if (command == "bench") return sdfstream::cli::runBench(argc, argv);
    if (command == "stress") return sdfstream::cli::runStress(argc, argv);
    std::fprintf(stderr, "sdfstream: unknown command '%s'\n%s", command.c_str(), kUsage);
    return 2;
  } catch (const sdfstream::InputError& e) {
    std::fprintf(stderr, "sdfstream %s: error [%s]: %s\n", command.c_str(),
                 sdfstream::toString(e.kind()), e.what());
    return e.kind() == sdfstream::InputErrorKind::Usage ? 2 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sdfstream %s: error: %s\n", command.c_str(), e.what());
    return 1;
  }
}
