// Where the built-in demo scene (demo/default_scene.json) is found at run time, so an installed
// or packaged binary works without the source tree. Candidates, in order, relative to the
// running executable (/proc/self/exe):
//   1. ../share/sdfstream/default_scene.json   the install layout (bin/sdfstream)
//   2. share/sdfstream/default_scene.json      scripts/package-gpu's (sdfstream-gpu/sdfstream)
//   3. the source tree's demo/default_scene.json, as compiled in (a build tree)
#pragma once

#include <filesystem>
#include <vector>

namespace sdfstream {

// The candidates for an executable at `executable`, in lookup order.
std::vector<std::filesystem::path> defaultSceneCandidates(const std::filesystem::path& executable);

// The first of `candidates` that is a file. Throws InputError (MissingData) naming every place
// looked.
std::filesystem::path findDefaultScene(const std::vector<std::filesystem::path>& candidates);
// The same for the running executable's candidates.
std::filesystem::path findDefaultScene();

}  // namespace sdfstream
