#include "crops.h"

#include "font.h"

#include <algorithm>

namespace steadyxr::eval {

namespace {

constexpr int kGap = 4;                             // pixels between columns
constexpr int kLabelHeight = kGlyphHeight * 2 + 6;  // labels drawn at 2x

void label(Image* canvas, const std::string& text, int x, int y, int maxWidth) {
  const float ink[3] = {0.0f, 0.0f, 0.0f};
  const int scale = textWidth(text, 2) <= maxWidth ? 2 : 1;
  drawText(canvas, text, x + std::max(0, (maxWidth - textWidth(text, scale)) / 2), y + 3, ink, scale);
}

}  // namespace

CropWindow centreCrop(int imageWidth, int imageHeight) {
  CropWindow w;
  w.width = std::max(8, imageWidth / 5);
  w.height = std::max(8, imageHeight / 5);
  w.x0 = imageWidth / 2 - w.width / 2;
  w.y0 = imageHeight / 2 - w.height / 2;
  return w;
}

bool writeCropStrip(const std::string& path, const std::vector<Tile>& tiles, const Image& truth,
                    const CropWindow& window, const std::string& caption, std::string* error) {
  const int cw = window.width * window.scale, ch = window.height * window.scale;
  const int columns = int(tiles.size()) + 1;
  const int captionHeight = kGlyphHeight + 6;
  Image canvas(columns * (cw + kGap), captionHeight + kLabelHeight + 2 * (ch + kGap), 1.0f);
  const float ink[3] = {0.2f, 0.2f, 0.2f};
  drawText(&canvas, caption, 2, 3, ink);
  const int top = captionHeight + kLabelHeight;
  for (int i = 0; i < columns; ++i) {
    const Image& img = i == 0 ? truth : tiles[size_t(i) - 1].image;
    const int x = i * (cw + kGap);
    label(&canvas, i == 0 ? "gt" : tiles[size_t(i) - 1].label, x, captionHeight, cw);
    blit(&canvas, cropMagnify(img, window.x0, window.y0, window.width, window.height, window.scale), x, top);
    blit(&canvas,
         cropMagnify(differenceImage(img, truth, 4.0f), window.x0, window.y0, window.width, window.height,
                     window.scale),
         x, top + ch + kGap);
  }
  return savePng(path, canvas, error);
}

bool writeAnimationFrame(const std::string& path, const std::vector<Tile>& tiles, const CropWindow& window,
                         std::string* error) {
  const int cw = window.width * window.scale, ch = window.height * window.scale;
  Image canvas(int(tiles.size()) * (cw + kGap), kLabelHeight + ch, 1.0f);
  for (size_t i = 0; i < tiles.size(); ++i) {
    const int x = int(i) * (cw + kGap);
    label(&canvas, tiles[i].label, x, 0, cw);
    blit(&canvas,
         cropMagnify(tiles[i].image, window.x0, window.y0, window.width, window.height, window.scale), x,
         kLabelHeight);
  }
  return savePng(path, canvas, error);
}

}  // namespace steadyxr::eval
