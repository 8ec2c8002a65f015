// Procedural high-frequency pictures for the image-viewer scenes, made at the size the picture
// plane covers on screen, so that one texel is about one screen pixel and "up to Nyquist" and
// "one-pixel lines" mean the screen's Nyquist and pixels.
#pragma once

#include "image.h"

#include <string>
#include <vector>

namespace steadyxr::eval {

// zoneplate (radial, frequency rising linearly to 0.5 cycles/px at the corners), lines1px (a grid of
// one-pixel lines every 3 px), hatch (one-pixel diagonal hatching, both directions in halves),
// smalltext (5x7 text, 1 px per font pixel), darkgradient (a horizontal ramp over the darkest
// 16 % of display values: where 8-bit steps and sRGB decoding matter).
const std::vector<std::string>& proceduralPictureNames();
bool isProceduralPicture(const std::string& name);
// screenHeight: the eye image height the run renders at (the picture is made to match it).
Rgba8 proceduralPicture(const std::string& name, int screenHeight);
// The picture class for the corpus table: photo, texture, synthetic (the procedural line art), dark.
std::string pictureClass(const std::string& name);

}  // namespace steadyxr::eval
