#pragma once
// A 5x7 bitmap font for chart text (plot.hpp): digits, upper- and lower-case letters and
// . - / ^ ( ) % + : , = _ and space. Glyphs were drawn for this project on a 5x7 cell with one
// blank column of spacing; characters without a glyph draw as '?'.
#include <string_view>

namespace msim::render::font {

inline constexpr int kGlyphWidth = 5;
inline constexpr int kGlyphHeight = 7;
inline constexpr int kAdvance = kGlyphWidth + 1;  // glyph plus one blank column

// True if the pixel (column, row) of c's glyph is ink; row 0 is the top.
bool ink(char c, int column, int row);
// Width in pixels of a line of text drawn at an integer `scale` (no trailing spacing column).
int textWidth(std::string_view text, int scale);

}  // namespace msim::render::font
