// `sdfstream view --script FILE`: scripted input, so a window can be driven without a person
// (tests under Xvfb, recorded fly-throughs). One command a line, run in order; '#' starts a
// comment:
//   camera px,py,pz,tx,ty,tz[,fov]  jump there before the next frame (metres, degrees)
//   hold KEY[+KEY...] N              hold the keys for the next N frames (e.g. hold W+LSHIFT 30)
//   press KEY                        press the key in the next frame (e.g. press V)
//   look DX DY                       mouse motion in the next frame, pixels
//   wheel N                          scroll N steps in the next frame
//   frames N                         N frames without input
//   settle                           before the next frame, stream until no page is missing
//                                    (no GI frames meanwhile: runs stay reproducible)
//   capture NAME                     write the frame last presented to OUT/NAME.png
//   quit                             close the window (the script's end does too)
// Key names are those of view --help (view_input.h).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gi/camera.h"
#include "viewer/view_input.h"

namespace sdfstream::viewer {

// One scripted frame: what happens before it, its input, and what is written after it.
struct ScriptFrame {
  std::optional<Camera> camera;  // jump here first
  bool settle = false;           // stream until nothing is missing first
  FrameInput input;
  std::vector<std::string> captures;  // names of OUT/NAME.png written after the frame
};

// The frames a script describes. Throws InputError naming `file` and the line for an unknown
// command or key, a bad number, a capture before any frame, or a capture name that is not a
// plain file name.
std::vector<ScriptFrame> parseViewScript(std::string_view text, const std::string& file);
std::vector<ScriptFrame> readViewScript(const std::filesystem::path& path);

}  // namespace sdfstream::viewer
