// view/: words in pictures (view/text.h) — the bitmap font, and the labelled row of panels
// prtview's triptychs are made of, with the error map's colour ramp (view/image.h error_colour).
#include <view/image.h>
#include <view/text.h>

#include <gtest/gtest.h>

#include <array>
#include <set>
#include <string>

using namespace prt::view;

TEST(Font, EveryPrintableGlyphIsItsOwnAndOthersAreAQuestionMark) {
  // 95 glyphs, no two alike (a copy-paste slip in the table shows here), all but the space
  // inked, none wider than 5 columns; bytes outside 32–126 draw as '?'.
  std::set<std::array<uint8_t, kGlyphRows>> seen;
  for (int c = 32; c <= 126; ++c) {
    const auto g = glyph(char(c));
    int ink = 0;
    for (uint8_t row : g) {
      EXPECT_LT(row, 1 << kGlyphColumns) << char(c);
      ink += __builtin_popcount(row);
    }
    EXPECT_EQ(ink == 0, c == ' ') << char(c);
    EXPECT_TRUE(seen.insert(g).second) << "glyph of '" << char(c) << "' repeats another";
  }
  EXPECT_EQ(glyph('\n'), glyph('?'));
  EXPECT_EQ(glyph(char(0xC3)), glyph('?'));
}

TEST(Font, WidthsCutsAndClipping) {
  EXPECT_EQ(text_width(""), 0);
  EXPECT_EQ(text_width("a"), 5);
  EXPECT_EQ(text_width("ab", 2), 22);
  EXPECT_EQ(fit_text("reference", 100), "reference");
  EXPECT_EQ(fit_text("reference (ray traced)", 59), "referen...");  // 10 characters take 6 x 10 - 1 = 59 columns
  EXPECT_EQ(fit_text("reference (ray traced)", 58), "refere...");
  EXPECT_LE(text_width(fit_text("reference (ray traced)", 59)), 59);
  EXPECT_EQ(fit_text("abc", 4), "");
  // Drawn text sets exactly the glyph's pixels; text running off the image is clipped.
  Image8 im(8, 9, 255);
  draw_text(im, 1, 1, "L", {0, 0, 0});
  const auto g = glyph('L');
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 8; ++x) {
      const bool on = x >= 1 && x < 6 && y >= 1 && y < 9 && (g[size_t(y - 1)] >> (4 - (x - 1)) & 1);
      EXPECT_EQ(im.rgb[3 * size_t(y * 8 + x)], on ? 0 : 255) << x << "," << y;
    }
  draw_text(im, -3, 5, "WWWW", {0, 0, 0}, 3);  // mostly outside: no crash, no write outside
  EXPECT_EQ(im.rgb.size(), size_t(8 * 9 * 3));
}

TEST(LabelledRow, CaptionsAboveTheUntouchedPicturesAndTheErrorScaleBelow) {
  // Two 60 x 40 panels: the caption strip (3 + 10 + 3 rows) holds the caption's ink on white,
  // the pictures are copied unchanged, the error panel's ramp runs from error_colour(0) to
  // error_colour(1), and the footer line is drawn under everything.
  Image8 a(60, 40, 10), b(60, 40, 200);
  const Panel panels[2] = {{a, "baked", std::nullopt}, {b, "error x10", std::array<std::string, 2>{"0", "10%"}}};
  const std::string footer[1] = {"RMSE 0.01"};
  const Image8 out = labelled_row(panels, footer);
  const int caption = 2 * kCaptionPad + kLineHeight, scale = 2 * kCaptionPad + 2 * kLineHeight, foot = kLineHeight + kCaptionPad;
  ASSERT_EQ(out.width, 124);
  ASSERT_EQ(out.height, caption + 40 + scale + foot);
  const auto px = [&](int x, int y) { return std::array<uint8_t, 3>{out.rgb[3 * size_t(y * out.width + x)], out.rgb[3 * size_t(y * out.width + x) + 1], out.rgb[3 * size_t(y * out.width + x) + 2]}; };
  // The caption, pixel for pixel: "baked" drawn alone on white at the same place.
  Image8 expect(60, caption, 255);
  draw_text(expect, kCaptionPad, kCaptionPad, "baked", {0, 0, 0});
  int ink = 0;
  for (int y = 0; y < caption; ++y)
    for (int x = 0; x < 60; ++x) {
      EXPECT_EQ(px(x, y)[0], expect.rgb[3 * size_t(y * 60 + x)]) << x << "," << y;
      ink += px(x, y)[0] == 0;
    }
  EXPECT_GT(ink, 20);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 60; ++x) {
      EXPECT_EQ(px(x, caption + y)[0], 10);
      EXPECT_EQ(px(64 + x, caption + y)[0], 200);
    }
  const int bar = caption + 40 + kCaptionPad;
  EXPECT_EQ(px(64 + kCaptionPad, bar), error_colour(0));
  EXPECT_EQ(px(64 + 60 - kCaptionPad - 1, bar), error_colour(1));
  EXPECT_EQ(px(kCaptionPad, bar), (std::array<uint8_t, 3>{255, 255, 255})) << "no scale under the first panel";
  int footer_ink = 0;
  for (int y = caption + 40 + scale; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) footer_ink += px(x, y)[0] == 0;
  EXPECT_GT(footer_ink, 20);
}

TEST(LabelledRow, ErrorColourIsTheRampOfTheErrorMap) {
  // false_colour_error colours an error e (relative to the range) as error_colour(e / full scale).
  Image test(5, 1), ref(5, 1);
  const double t[5] = {0, 0.25, 0.4, 0.75, 2};
  for (int x = 0; x < 5; ++x)
    for (int c = 0; c < 3; ++c) test.at(x, 0)[c] = float(0.1 * t[x]);  // range 1, full scale 0.1
  const Image8 err = false_colour_error(test, ref, {}, 1.0, 0.1);
  for (int x = 0; x < 5; ++x) {
    const auto want = error_colour(t[x]);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(err.rgb[size_t(3 * x + c)], want[size_t(c)], 1) << x;
  }
  EXPECT_EQ(error_colour(0), (std::array<uint8_t, 3>{0, 0, 0}));
  EXPECT_EQ(error_colour(1), (std::array<uint8_t, 3>{255, 250, 190}));
}
