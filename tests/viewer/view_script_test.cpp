// The --script reader: commands become frames with the right input, and every mistake names the
// file and the line.
#include <gtest/gtest.h>

#include <string>

#include "core/error.h"
#include "viewer/view_script.h"

namespace sdfstream::viewer {
namespace {

TEST(ViewScript, CommandsBecomeFramesWithTheirInput) {
  const auto frames = parseViewScript(
      "# comment\n"
      "camera 1,2,3,1,2,0\n"
      "settle\n"
      "hold W+LSHIFT 2   # two frames\n"
      "press v\n"
      "look 10 -5\n"
      "wheel 2\n"
      "frames 1\n"
      "capture first\n"
      "frames 2\n"
      "capture last\n"
      "quit\n"
      "frames 100\n",
      "s.txt");
  ASSERT_EQ(frames.size(), 5u);
  ASSERT_TRUE(frames[0].camera);
  EXPECT_EQ(frames[0].camera->position, glm::dvec3(1, 2, 3));
  EXPECT_TRUE(frames[0].settle);
  for (int f : {0, 1}) {
    EXPECT_TRUE(frames[f].input.held[int(Action::Forward)]);
    EXPECT_TRUE(frames[f].input.held[int(Action::Fast)]);
    EXPECT_FALSE(frames[f].input.held[int(Action::Back)]);
  }
  EXPECT_FALSE(frames[1].camera);
  EXPECT_FALSE(frames[1].settle);
  EXPECT_FALSE(frames[2].input.held[int(Action::Forward)]);
  EXPECT_EQ(frames[2].input.presses[int(Action::NextView)], 1);
  EXPECT_EQ(frames[2].input.look, glm::dvec2(10, -5));
  EXPECT_EQ(frames[2].input.wheel, 2.0);
  EXPECT_EQ(frames[2].captures, std::vector<std::string>{"first"});
  EXPECT_TRUE(frames[3].captures.empty());
  EXPECT_EQ(frames[4].captures, std::vector<std::string>{"last"});  // quit ends the script
}

TEST(ViewScript, APressWithNoFrameAfterItStillGetsOne) {
  const auto frames = parseViewScript("frames 1\npress F12\n", "s.txt");
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[1].input.presses[int(Action::Screenshot)], 1);
}

TEST(ViewScript, MistakesNameTheFileAndLine) {
  const std::pair<const char*, const char*> cases[] = {
      {"frames 1\njump 3\n", "s.txt: line 2: unknown command 'jump'"},
      {"hold X 3\n", "line 1: unknown key 'X'"},
      {"frames -1\n", "line 1: '-1' is not a frame count"},
      {"look 1 nan\n", "line 1: 'nan' is not a finite number"},
      {"capture a\n", "line 1: capture before any frame"},
      {"frames 1\ncapture ../a\n", "line 2: capture ../a: expected a plain file name"},
      {"camera 1,2\n", "line 1: '1,2' is not a camera"},
      {"frames 1 2\n", "line 1: unexpected '2' after frames"},
      {"hold W\n", "line 1: expected a frame count"},
  };
  for (const auto& [text, message] : cases) {
    try {
      parseViewScript(text, "s.txt");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos)
          << text << " -> " << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  }
}

TEST(ViewScript, EveryKeyNameRoundTrips) {
  for (int a = 0; a < kActionCount; ++a) {
    const auto back = actionOfKey(keyName(Action(a)));
    ASSERT_TRUE(back);
    EXPECT_EQ(int(*back), a);
    EXPECT_NE(keyHelp().find(std::string(keyName(Action(a)))), std::string::npos);
  }
  EXPECT_FALSE(actionOfKey("NOPE"));
}

}  // namespace
}  // namespace sdfstream::viewer
