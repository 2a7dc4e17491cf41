#pragma once
// How much fine detail a picture holds: the share of its luminance's spectral energy at radial
// frequencies above half the Nyquist frequency (features under four pixels across). A smooth
// smear scores near 0; wisps, curls and sharp edges raise it. Used to compare two pictures of the
// same camera and frame (the default scene with and without its turbulent wind).
#include "msim/io/png.hpp"

namespace msim::render {

// The pixels x0 <= x < x1, y0 <= y < y1 (y from the top) of a picture.
struct PixelBox {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

// Luminance (Rec. 709 weights) with its mean removed, times a Hann window in both directions
// (so the picture's borders add no jump), transformed by FFT; the power above radial frequency
// 0.25 cycles per pixel over the power at every nonzero frequency. 0 for a uniform picture.
// std::invalid_argument for a box that is empty or leaves the picture.
double fineDetailShare(const io::Image& picture, const PixelBox& box);
double fineDetailShare(const io::Image& picture);

}  // namespace msim::render
