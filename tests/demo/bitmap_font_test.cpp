#include <gtest/gtest.h>

#include "demo/bitmap_font.h"

namespace sdfstream {
namespace {

int litPixels(const font::Glyph& g) {
  int n = 0;
  for (auto row : g) n += __builtin_popcount(row);
  return n;
}

TEST(BitmapFont, EveryPrintableCharacterButSpaceHasInk) {
  EXPECT_EQ(litPixels(font::glyph(' ')), 0);
  for (int c = 33; c <= 126; ++c) EXPECT_GT(litPixels(font::glyph(char(c))), 0) << char(c);
}

TEST(BitmapFont, GlyphsFitTheirCellAndAreDistinct) {
  for (int c = 32; c <= 126; ++c) {
    for (auto row : font::glyph(char(c))) EXPECT_LT(row, 1 << font::kGlyphWidth) << char(c);
    // Two characters drawing the same way would make labels ambiguous.
    for (int d = 32; d < c; ++d)
      EXPECT_NE(font::glyph(char(c)), font::glyph(char(d))) << char(c) << " vs " << char(d);
  }
}

TEST(BitmapFont, NonAsciiDrawsAsQuestionMark) {
  EXPECT_EQ(font::glyph('\x01'), font::glyph('?'));
  EXPECT_EQ(font::glyph(char(0xE9)), font::glyph('?'));
}

TEST(BitmapFont, DrawTextScalesAndClips) {
  Image8 img{40, 20, std::vector<std::uint8_t>(40 * 20 * 3, 255)};
  font::drawText(img, 0, 0, "I", {0, 0, 0}, 2);
  // 'I' has a 3-pixel top bar in columns 1..3, so at scale 2 pixels (2..7, 0..1) are black.
  auto at = [&](int x, int y) { return img.rgb[(std::size_t(y) * img.width + x) * 3]; };
  EXPECT_EQ(at(2, 0), 0);
  EXPECT_EQ(at(7, 1), 0);
  EXPECT_EQ(at(0, 0), 255);
  EXPECT_EQ(at(8, 0), 255);
  EXPECT_EQ(font::textWidth("ab", 2), (2 * font::kAdvance - 1) * 2);
  font::drawText(img, 35, 15, "WWW", {0, 0, 0}, 2);  // partly outside: must not write out of bounds
  font::drawTextUp(img, -3, -3, "WWW", {0, 0, 0}, 2);
}

TEST(BitmapFont, DrawTextUpReadsBottomToTop) {
  Image8 img{10, 20, std::vector<std::uint8_t>(10 * 20 * 3, 255)};
  font::drawTextUp(img, 0, 0, "L", {0, 0, 0});
  auto black = [&](int x, int y) { return img.rgb[(std::size_t(y) * img.width + x) * 3] == 0; };
  // 'L' is a left stem plus a bottom bar; rotated CCW the stem becomes the bottom row (y = 4)
  // and the bar the right column (x = 6), running up from the bottom.
  for (int x = 0; x <= 6; ++x) EXPECT_TRUE(black(x, 4)) << x;
  for (int y = 0; y <= 4; ++y) EXPECT_TRUE(black(6, y)) << y;
  EXPECT_FALSE(black(0, 0));
}

}  // namespace
}  // namespace sdfstream
