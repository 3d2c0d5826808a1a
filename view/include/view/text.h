// view/text.h — words in pictures: a small built-in bitmap font and the labelled row of panels
// prtview writes (a triptych whose panels say what they are, with the error panel's colour scale
// and a summary line). Pixel conventions: view/image.h; layers: docs/ARCHITECTURE.md §2.
//
// FONT. Our own glyph table (text.cpp) for printable ASCII 32–126: each glyph is 5 columns × 8
// rows of on/off pixels, capitals and digits in rows 0–6, row 7 for the descenders of g j p q y
// and , ; every other byte is drawn as '?'. A character advances 6 columns (5 + 1 of spacing);
// a line is 10 rows (8 + 2). `scale` draws each font pixel as a scale × scale square. No
// anti-aliasing, no kerning: the same text gives the same pixels everywhere.
//
// LABELLED ROW (labelled_row). Panels side by side, `gap` white columns apart, on white:
//   caption strip  kCaptionPad rows, the caption (black, left-aligned kCaptionPad columns in;
//                  cut to the panel's width with "..." when it does not fit), kCaptionPad rows;
//   the pictures   top-aligned;
//   scale strip    (when any panel has a colour scale) under such a panel: the ramp of
//                  false_colour_error from t = 0 (left) to 1 (right), one line high, and its two
//                  end labels under its ends;
//   footer         each footer line (black), cut to the row's width.
// Every strip height is a whole number of text lines, so the layout depends only on the
// panels' sizes, the number of footer lines and `scale`.
#pragma once

#include <view/image.h>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace prt::view {

inline constexpr int kGlyphColumns = 5, kGlyphRows = 8;
inline constexpr int kCharAdvance = 6, kLineHeight = 10;
inline constexpr int kCaptionPad = 3;

// The glyph of `c`: row r's bit (4 − x) is column x (bit 4 = leftmost). '?' for bytes outside 32–126.
std::array<uint8_t, kGlyphRows> glyph(char c);
// Width in pixels of `text` drawn at `scale`: kCharAdvance · scale per character, without the
// spacing after the last one (0 for empty text).
int text_width(std::string_view text, int scale = 1);
// Draws `text` with the top-left of its first glyph cell at (x, y) in `colour`; only the glyphs'
// "on" pixels are written; pixels outside the image are skipped.
void draw_text(Image8& image, int x, int y, std::string_view text, std::array<uint8_t, 3> colour, int scale = 1);
// `text` cut so that text_width(result, scale) <= width: the longest prefix followed by "..."
// (or fewer dots when even that does not fit); unchanged when it fits.
std::string fit_text(std::string_view text, int width, int scale = 1);

// One panel of a labelled row.
struct Panel {
  Image8 picture;
  std::string caption;
  // Error panels: labels of the two ends of the false-colour ramp (view/image.h error_colour),
  // e.g. {"0", "10% of range"}; the ramp is drawn under the picture.
  std::optional<std::array<std::string, 2>> scale;
};
Image8 labelled_row(std::span<const Panel> panels, std::span<const std::string> footer, int scale = 1, int gap = 4);

} // namespace prt::view
