// A tiny RGB raster for the report pictures (heatmap.png, reduction.png): filled shapes, a
// built-in 5x7 bitmap font, the viridis colour map and PNG encoding with libpng. Internal to
// vc_core; thread-compatible.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vc/base/status.h"

namespace vc::raster {

using Rgb = std::array<uint8_t, 3>;

inline constexpr Rgb kWhite{255, 255, 255};
inline constexpr Rgb kBlack{0, 0, 0};
inline constexpr Rgb kGrey{200, 200, 200};
inline constexpr Rgb kDarkGrey{90, 90, 90};
inline constexpr Rgb kRed{215, 40, 40};
inline constexpr Rgb kOrange{255, 140, 0};

// Font cell: glyphs are 5 x 7 pixels, advanced 6 pixels, at integer `scale`.
inline constexpr int kGlyphW = 5, kGlyphH = 7, kAdvance = 6;

class Image {
 public:
  Image(int width, int height, Rgb background = kWhite);
  int width() const { return w_; }
  int height() const { return h_; }
  const std::vector<uint8_t>& pixels() const { return px_; }  // row-major RGB
  Rgb at(int x, int y) const;

  void Set(int x, int y, Rgb c);
  // Axis-aligned rectangle [x0, x1) x [y0, y1), clipped.
  void FillRect(int x0, int y0, int x1, int y1, Rgb c);
  // One-pixel rectangle outline around [x0, x1) x [y0, y1).
  void StrokeRect(int x0, int y0, int x1, int y1, Rgb c);
  void FillCircle(int cx, int cy, int radius, Rgb c);
  void HLine(int x0, int x1, int y, Rgb c);
  void VLine(int x, int y0, int y1, Rgb c);
  // A straight segment from (x0, y0) to (x1, y1), `width` pixels wide (discs along it), clipped.
  void Line(int x0, int y0, int x1, int y1, Rgb c, int width = 1);
  // UTF-8 text with its top-left corner at (x, y). Digits, A-Z, lower-case m x y z, and
  // . - , : ( ) % = / + [ ] ' < > ≤ ≥ space; other lower-case letters are drawn as
  // capitals, anything else as a box.
  void Text(int x, int y, std::string_view text, Rgb c, int scale = 1);
  // The same text rotated 90 degrees counter-clockwise (reading bottom to top), top-left at (x, y).
  void TextVertical(int x, int y, std::string_view text, Rgb c, int scale = 1);

 private:
  int w_, h_;
  std::vector<uint8_t> px_;
};

// Pixel width of UTF-8 `text` at `scale`.
int TextWidth(std::string_view text, int scale = 1);

// Viridis colour of t in [0, 1] (clamped; NaN gives 0).
Rgb Viridis(double t);

// PNG bytes of `image` (8-bit RGB). INTERNAL if libpng fails.
Result<std::string> EncodePng(const Image& image);

}  // namespace vc::raster
