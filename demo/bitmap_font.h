// A built-in 5x7 bitmap font (plus one descender row) so charts need no font files or libraries.
// Glyphs cover printable ASCII 32..126; anything else draws as '?'.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

#include <glm/glm.hpp>

#include "demo/frame_image.h"

namespace sdfstream::font {

inline constexpr int kGlyphWidth = 5;
inline constexpr int kGlyphRows = 8;    // 7 rows above the baseline + 1 descender row (g, p, _)
inline constexpr int kAdvance = 6;      // glyph width + 1 column of spacing
inline constexpr int kLineHeight = 10;  // glyph rows + 2 rows of spacing

// Rows of a glyph, top first; bit 4 is the leftmost column.
using Glyph = std::array<std::uint8_t, kGlyphRows>;
const Glyph& glyph(char c);

// Size in pixels of a single line of text at an integer scale (no trailing spacing column).
int textWidth(std::string_view text, int scale = 1);
inline int textHeight(int scale = 1) { return kGlyphRows * scale; }

// Draws text with its top-left corner at (x, y); pixels outside the image are clipped.
void drawText(Image8& image, int x, int y, std::string_view text, glm::u8vec3 color, int scale = 1);
// Draws text rotated 90 degrees counter-clockwise (reading bottom to top), for vertical axis
// labels; (x, y) is the top-left corner of the rotated text's bounding box.
void drawTextUp(Image8& image, int x, int y, std::string_view text, glm::u8vec3 color,
                int scale = 1);

}  // namespace sdfstream::font
