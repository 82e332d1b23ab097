// The command-line flags every rendering command shares (--gi, --gi-frames, --probe-rays,
// --probe-budget, --relight-pages, --sun, --sky, --exposure, --direct), their help text and their
// parsing into RenderOptions (demo/render_options.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <set>
#include <string>

#include "demo/render_options.h"
#include "tools/args.h"

namespace sdfstream::cli {

// Value options to add to a command's Args (besides its own).
std::set<std::string> renderValueOptions(std::set<std::string> own);
// The help text of the shared rendering flags (lines starting with two spaces), without
// --gi-frames, whose meaning differs: kStillGiFramesHelp is render's and demo's.
extern const char* const kRenderHelp;
extern const char* const kStillGiFramesHelp;
// Parses the shared flags. cpu: the command runs without Vulkan, so GI is off (an explicit
// `--gi on` is a usage error). defaultGiFrames / defaultProbeBudget: the command's defaults for
// --gi-frames, --probe-budget and --relight-pages (kProbeBudgetOfDevice, kRelightBudgetOfDevice:
// chosen by device once it is open).
RenderOptions renderOptionsFromArgs(const Args& args, bool cpu, int defaultGiFrames,
                                    std::uint32_t defaultProbeBudget = probe::kDefaultProbeRayBudget,
                                    std::uint32_t defaultRelightBudget = kRelightEveryPage);

// --mesh FILE and --primary raster|sdf (render, view; add both to the command's value options):
// the mesh scene whose triangles are rasterized as the primary surfaces
// (StreamedGiOptions::primaryMesh), or empty for the SDF's. --mesh alone means raster;
// --primary raster without --mesh, or with --cpu, is a usage error.
extern const char* const kPrimaryHelp;
std::filesystem::path primaryMeshFromArgs(const Args& args, bool cpu);

}  // namespace sdfstream::cli
