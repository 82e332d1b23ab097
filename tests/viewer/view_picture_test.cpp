// The viewer's pictures: debug views read the shaded hits (misses stay black), scaling is
// nearest-neighbour, the HUD darkens its band and writes text.
#include <gtest/gtest.h>

#include "viewer/view_picture.h"

namespace sdfstream::viewer {
namespace {

struct TwoPixels {
  ShadedView view;
  HdrFrame frame;
  TwoPixels() {
    view.width = frame.width = 2;
    view.height = frame.height = 1;
    view.shaded.resize(2);
    gpu_shared::ShadedHit& hit = view.shaded[0];
    hit.flags = gpu_shared::kHitFlagHit | (3u << gpu_shared::kHitCascadeShift);
    hit.albedo = 10u | (20u << 8) | (30u << 16) | (255u << 24);
    hit.normalT = glm::vec4(0.0f, 1.0f, 0.0f, 5.0f);
    frame.direct = {glm::vec3(0.5f), glm::vec3(0.2f)};
    frame.indirect = {glm::vec3(0.5f), glm::vec3(0.0f)};
  }
};

TEST(ViewPicture, DebugViewsReadTheHitsAndLeaveMissesBlack) {
  const TwoPixels p;
  const Image8 albedo = viewPicture(ViewMode::Albedo, p.view, p.frame, true, 0.0f);
  EXPECT_EQ((std::vector<std::uint8_t>(albedo.rgb.begin(), albedo.rgb.begin() + 3)),
            (std::vector<std::uint8_t>{10, 20, 30}));
  const Image8 normals = viewPicture(ViewMode::Normals, p.view, p.frame, true, 0.0f);
  EXPECT_EQ(normals.rgb[0], 128);
  EXPECT_EQ(normals.rgb[1], 255);
  EXPECT_EQ(normals.rgb[2], 128);
  const Image8 cascade = viewPicture(ViewMode::Cascade, p.view, p.frame, true, 0.0f);
  const Image8 cascade0 = [&] {
    TwoPixels q;
    q.view.shaded[0].flags = gpu_shared::kHitFlagHit;
    return viewPicture(ViewMode::Cascade, q.view, q.frame, true, 0.0f);
  }();
  EXPECT_NE(std::vector<std::uint8_t>(cascade.rgb.begin(), cascade.rgb.begin() + 3),
            std::vector<std::uint8_t>(cascade0.rgb.begin(), cascade0.rgb.begin() + 3));
  for (const Image8* image : {&albedo, &normals, &cascade})
    EXPECT_EQ((std::vector<std::uint8_t>(image->rgb.begin() + 3, image->rgb.end())),
              (std::vector<std::uint8_t>{0, 0, 0}));
}

TEST(ViewPicture, FinalWithoutIndirectIsTheDirectPicture) {
  const TwoPixels p;
  EXPECT_EQ(viewPicture(ViewMode::Final, p.view, p.frame, false, 0.0f).rgb,
            viewPicture(ViewMode::Direct, p.view, p.frame, true, 0.0f).rgb);
  EXPECT_NE(viewPicture(ViewMode::Final, p.view, p.frame, true, 0.0f).rgb,
            viewPicture(ViewMode::Direct, p.view, p.frame, true, 0.0f).rgb);
}

TEST(ViewPicture, ScaleNearestRepeatsPixels) {
  const Image8 small{2, 1, {1, 2, 3, 4, 5, 6}};
  const Image8 big = scaleNearest(small, 4, 2);
  ASSERT_EQ(big.rgb.size(), 24u);
  const std::vector<std::uint8_t> row{1, 2, 3, 1, 2, 3, 4, 5, 6, 4, 5, 6};
  EXPECT_EQ(std::vector<std::uint8_t>(big.rgb.begin(), big.rgb.begin() + 12), row);
  EXPECT_EQ(std::vector<std::uint8_t>(big.rgb.begin() + 12, big.rgb.end()), row);
}

TEST(ViewPicture, HudDarkensItsBandAndWritesText) {
  Image8 image{200, 60, std::vector<std::uint8_t>(200 * 60 * 3, 90)};
  drawHud(image, {"fps 60", "GI on"}, 1);
  int bright = 0, dark = 0;
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 40; ++x) {
      const std::uint8_t v = image.rgb[3 * (y * 200 + x)];
      bright += v > 200;
      dark += v == 30;
    }
  EXPECT_GT(bright, 20);                           // glyph pixels
  EXPECT_GT(dark, 200);                            // the darkened band
  EXPECT_EQ(image.rgb[3 * (59 * 200 + 199)], 90);  // outside the band: untouched
}

}  // namespace
}  // namespace sdfstream::viewer
