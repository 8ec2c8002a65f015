// What a person sees: labelled, magnified crops of a case (the worst frame and the last one) and
// the frames of a short animated side-by-side comparison (eval/plot.py assembles the GIF).
#pragma once

#include "image.h"

#include <string>
#include <vector>

namespace steadyxr::eval {

struct Tile {
  std::string label;
  Image image;  // full eye image (left eye)
};

struct CropWindow {
  int x0 = 0, y0 = 0, width = 8, height = 8, scale = 4;
};
// The centre fifth of the image, magnified 4x (seed 003 Fig. 4's crops).
CropWindow centreCrop(int imageWidth, int imageHeight);

// Row 1: each tile's crop, its label drawn above it; row 2: |tile - truth| x4. The truth is the
// first column, labelled "gt".
bool writeCropStrip(const std::string& path, const std::vector<Tile>& tiles, const Image& truth,
                    const CropWindow& window, const std::string& caption, std::string* error);
// One frame of the animation: the tiles' crops side by side, labelled, no difference row.
bool writeAnimationFrame(const std::string& path, const std::vector<Tile>& tiles, const CropWindow& window,
                         std::string* error);

}  // namespace steadyxr::eval
