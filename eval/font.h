// A tiny built-in 5x7 bitmap font (upper case, digits, a little punctuation; lower case is drawn
// as upper case): labels on the crop strips and the harness's small-text picture.
#pragma once

#include "image.h"

#include <string>

namespace steadyxr::eval {

inline constexpr int kGlyphWidth = 5, kGlyphHeight = 7, kGlyphAdvance = 6;

// Whether pixel (x, y) of the glyph of `c` is set (unknown characters are blank).
bool glyphPixel(char c, int x, int y);
// Draws `text` with its top-left corner at (x, y), each font pixel as scale x scale pixels.
void drawText(Image* image, const std::string& text, int x, int y, const float rgb[3], int scale = 1);
int textWidth(const std::string& text, int scale = 1);

}  // namespace steadyxr::eval
