#pragma once
// `msim spectrum FILE.vdb`: the kinetic energy spectrum of a saved 3D velocity field. The largest
// cube (an even number of voxels per side) that fits the grid is cut out, centred on the smoke
// (the centroid of a "density" grid on the same voxels, if the file has one) or on the grid;
// a Hann window makes it periodic for the FFT; its shell spectrum (turbulence::shellSpectrum) is
// written as CSV and PNG, with a power-law fit over the middle of the resolved range.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace msim::scene {

struct SpectrumJob {
  std::vector<std::filesystem::path> inputs;  // .vdb files, compared in one chart
  std::string grid = "vel";                   // their vector grid
  std::filesystem::path output;  // prefix of <output>_N.csv (one per input) and <output>.png;
                                 // empty: <first input without .vdb>_spectrum
};

// Per input: the fitted exponent, the shells used, the cube's side and origin [voxels], the CSV;
// and the chart. InputError for a missing file or grid, or a grid thinner than 16 voxels.
nlohmann::json velocitySpectrum(const SpectrumJob& job);

}  // namespace msim::scene
