#include "msim/scene/reports/velocity_spectrum.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/parallel.hpp"
#include "msim/io/atomic_file.hpp"
#include "msim/io/png.hpp"
#include "msim/io/vdb.hpp"
#include "msim/scene/reports/spectrum_plot.hpp"
#include "msim/turbulence/energy_spectrum.hpp"

namespace msim::scene {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

struct Measured {
  turbulence::ShellSpectrum spectrum;
  json result;
};

Measured measure(const fs::path& input, const std::string& grid) {
  const io::VdbFile file(input, io::VdbProvenance::AnyTool);
  const Grid<Vecf<3>, 3> velocity = file.vectorGrid(grid);
  const IVec3 size = velocity.size();
  const int side = (size.minCoeff() / 2) * 2;
  if (side < 16)
    throw InputError(fmt::format("{}: grid '{}' is {} x {} x {} voxels; a spectrum needs a cube of at least 16",
                                 input.string(), grid, size.x(), size.y(), size.z()));
  // Centre: the smoke's centroid when the file holds a density on the same voxels.
  Vec3 centre = 0.5 * size.cast<double>();
  if (file.hasGrid("density")) {
    const Grid<float, 3> density = file.floatGrid("density");
    if (density.size() == size) {
      Vec3 moment = Vec3::Zero();
      double mass = 0.0;
      for (std::size_t i = 0; i < density.count(); ++i) {
        if (density[i] <= 0.0f) continue;
        moment += density[i] * density.coord(i).cast<double>();
        mass += density[i];
      }
      if (mass > 0.0) centre = moment / mass;
    }
  }
  IVec3 lo;
  for (int d = 0; d < 3; ++d)
    lo[d] = std::clamp(static_cast<int>(std::lround(centre[d] - side / 2.0)), 0, size[d] - side);
  // The cube times a 3D Hann window, rescaled so the window keeps the mean energy.
  const std::size_t n = static_cast<std::size_t>(side) * side * side;
  std::vector<Vecf<3>> cube(n);
  std::vector<double> window(static_cast<std::size_t>(side));
  for (int i = 0; i < side; ++i) window[i] = std::pow(std::sin(std::numbers::pi * (i + 0.5) / side), 2);
  double meanSquareWindow = 0.0;
  for (const double w : window) meanSquareWindow += w * w / side;
  const float scale = static_cast<float>(1.0 / std::sqrt(std::pow(meanSquareWindow, 3)));
  parallelForCells<3>(IVec3::Constant(side), [&](const IVec3& c, std::size_t lin) {
    const float w = static_cast<float>(window[c.x()] * window[c.y()] * window[c.z()]);
    cube[lin] = scale * w * velocity(IVec3(c + lo));
  });
  const double dx = velocity.spec().dx;
  const turbulence::ShellSpectrum spectrum = turbulence::shellSpectrum<3>(cube, side, side * dx);
  // Fit over shells 4 .. side / 4: above the window's smearing, below the grid's dissipation range.
  const double dk = 2.0 * std::numbers::pi / (side * dx);
  json result = {{"cube_voxels", side}, {"cube_origin_voxels", {lo.x(), lo.y(), lo.z()}}, {"voxel_size_m", dx}};
  try {
    const auto fit = turbulence::fitPowerLaw(spectrum, 3.5 * dk, side / 4.0 * dk);
    result["exponent"] = fit.exponent;
    result["shells_fitted"] = fit.points;
  } catch (const std::invalid_argument&) {
    result["exponent"] = nullptr;
  }
  result["file"] = input.string();
  return Measured{spectrum, result};
}

}  // namespace

json velocitySpectrum(const SpectrumJob& job) {
  if (job.inputs.empty()) throw InputError("msim spectrum: no .vdb file given");
  fs::path prefix = job.output;
  if (prefix.empty()) prefix = job.inputs.front().parent_path() / (job.inputs.front().stem().string() + "_spectrum");
  if (!prefix.parent_path().empty()) fs::create_directories(prefix.parent_path());
  json results = json::array();
  std::vector<SpectrumCurve> curves;
  for (std::size_t i = 0; i < job.inputs.size(); ++i) {
    Measured m = measure(job.inputs[i], job.grid);
    const fs::path csvFile = fmt::format("{}_{}.csv", prefix.string(), i);
    io::writeFileAtomically(csvFile, [&](const fs::path& tmp) {
      std::ofstream csv(tmp, std::ios::binary);
      csv << "k_rad_per_m,E,modes\n";
      for (std::size_t s = 0; s < m.spectrum.wavenumber.size(); ++s)
        csv << fmt::format("{:.6g},{:.6g},{}\n", m.spectrum.wavenumber[s], m.spectrum.energy[s], m.spectrum.modes[s]);
      if (!csv) throw std::runtime_error("writing " + csvFile.string() + " failed");
    });
    m.result["csv"] = csvFile.string();
    // Label: the run folder and the frame (runs name their frames alike).
    const fs::path& in = job.inputs[i];
    const std::string run = in.parent_path().filename() == "vdb" ? in.parent_path().parent_path().filename().string() : "";
    curves.push_back({run.empty() ? in.filename().string() : run + "/" + in.filename().string(), m.spectrum.wavenumber,
                      m.spectrum.energy, true});
    results.push_back(m.result);
  }
  const fs::path pngFile = prefix.string() + ".png";
  io::writePng(pngFile, render::renderPlot(spectrumPlot(fmt::format("energy spectrum of {}", job.grid), curves)));
  return json{{"spectra", results}, {"png", pngFile.string()}};
}

}  // namespace msim::scene
