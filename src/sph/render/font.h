#pragma once
/// \file A built-in bitmap font (printable ASCII) for labels, ticks, legends and captions.
///
/// Each glyph is 5 x 9 pixels at scale 1: a 7-pixel body (capitals and digits) above the
/// baseline and 2 rows of descenders below it; glyphs advance by 6 pixels (1 pixel of spacing).
/// Characters outside ASCII 32..126 draw as a box (a multi-byte UTF-8 character as one box).
/// `scale` multiplies every pixel into a scale x scale block; values below 1 count as 1.

#include <string_view>

#include <sph/render/image.h>

namespace sph {

/// Width in pixels of the ink box of `text`: 6 * scale per character minus the trailing spacing
/// (0 for an empty text). Single line: '\n' is drawn as a box like any other control character.
int text_width(std::string_view text, int scale = 1);

/// Height in pixels of a line of text, descenders included (9 * scale).
int text_height(int scale = 1);

/// Draws `text` with its top-left corner at pixel (x, y). All ink lies inside the
/// text_width(text, scale) x text_height(scale) box at (x, y); drawing is clipped to the image.
void draw_text(Image& image, int x, int y, std::string_view text, Rgb color, int scale = 1);

/// Draws `text` rotated a quarter turn counter-clockwise (reading upwards), as on a y-axis label.
/// Its box is text_height(scale) wide and text_width(text, scale) tall, with top-left at (x, y).
void draw_text_vertical(Image& image, int x, int y, std::string_view text, Rgb color, int scale = 1);

}  // namespace sph
