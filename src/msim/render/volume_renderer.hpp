#pragma once
// Physically based volume renderer for gridded smoke and fire (Stam ch. 5.1, single scattering with
// optional multiple-scattering fluence). Along each camera ray the integral form of the transport
// equation (eq. 5.8) is marched front to back through the grid's box:
//
//   I(x0, s) = I_background tau(x_b, x0) + integral_0^b tau(x_u, x0) [ sigma_t rho J ](x_u, s) du,
//   tau = exp(-sigma_t integral rho du)                                                 (eq. 5.6)
//
// with the source sigma_t rho J = sigma_t rho (Omega S{I} + (1 - Omega) Q) (eq. 5.9) made of
//   - single scattering of the lights (eq. 5.13, S{I} ~ S{I_ri}): for each light l
//       sigma_s rho E_l(x) T_l(x) p(s_l . s) / (4 pi),
//     E_l the unshadowed irradiance (light.hpp), T_l the transmittance from x to the light
//     (lightTransmittance), p the Henyey-Greenstein phase function normalised to 4 pi (eq. 5.2);
//   - sky light: a constant diffuse radiance I_d^0 = settings.ambient arriving from all directions
//     at every point, scattered as sigma_s rho I_d^0 (S of a constant is the constant). This is
//     Stam's "brightening" term (footnote to eq. 5.13), which he writes (1 - tau) I_d^0 (weight
//     sigma_t); we weight it by sigma_s = Omega sigma_t so an absorbing (Omega = 0) medium is not lit
//     by the sky, and, like Stam, ignore the self-shadowing of the sky light;
//   - multiple scattering, when a fluence grid phi = integral I_d ds' is given (the diffusion
//     solution of a colleague's solver, fed by firstScatterSource): sigma_s rho phi / (4 pi), the
//     isotropic part of Omega S{I_d} (exact for an isotropic phase function). The fluence is a
//     luminance; it takes the lights' chromaticity (sum of intensity * colour scaled to unit
//     luminance), which is exact for one light, or lights of one colour, as the medium is grey;
//   - emission (the (1 - Omega) Q term), see Medium.
// Samples are at the midpoints of steps of stepCells cells; over one step the medium is taken as
// constant, so the step integrates exactly: dI = T (1 - exp(-sigma_t rho ds)) / (sigma_t rho) *
// source, T *= exp(-sigma_t rho ds). Rays stop once T < 1e-4. Density (and the other grids) are
// sampled trilinearly between cell centres with the border value extended to the box faces; outside
// the box there is no medium. Bricks of cells with no density (and no emitter) are skipped, which
// changes nothing in the result: such samples would add exactly zero.
//
// Opaque surfaces end the march: obstacles given as a signed-distance grid (found by sphere
// tracing the trilinear distance, steps of at least the march step, refined by bisection), triangle
// meshes and point sets drawn as spheres (surfaces.hpp, through a BVH). Eq. 5.8 then holds with the
// surface's radiance in place of I_background at the hit: the medium in front attenuates it and adds
// its in-scattering as usual. The surfaces are Lambertian with albedo a:
//   L = a I_d^0 + (a / pi) sum_l E_l(x) max(n . s_l, 0) T_l(x') V_l(x),
// the first term the sky (irradiance pi I_d^0 from the open hemisphere, unshadowed as in the medium),
// T_l the light's transmittance grid sampled at x' two cells out along the normal (the grid's soft
// edge of the solid lies within a cell and a half of the surface, see lightTransmittance), V_l a
// shadow ray to the light through the meshes and spheres.
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/io/png.hpp"
#include "msim/render/camera.hpp"
#include "msim/render/environment.hpp"
#include "msim/render/light.hpp"
#include "msim/render/liquid_tracer.hpp"
#include "msim/render/surfaces.hpp"

namespace msim::render {

struct Medium {
  double extinction = 10.0;  // sigma_t per unit density [m^2/kg]: K_t = sigma_t rho
  double albedo = 0.9;       // Omega in [0, 1]: sigma_s = Omega sigma_t, sigma_a = (1 - Omega) sigma_t
  double phaseG = 0.0;       // Henyey-Greenstein asymmetry g in (-1, 1) (Stam's mu_bar = 3 g; phase_function.hpp)
  // Fire, with the black-body colour and T^4 brightness of BlackbodyTable(emissionReference):
  //  - with an emitter grid (the artist's form, the same as the preview's): the emitted radiance per
  //    metre is emissionScale * emitter(x) * B(T(x)), whatever the smoke's density and albedo, so
  //    the flame's brightness does not change when the smoke's look is tuned. In Stam's terms this
  //    is sigma_t rho (1 - Omega) Q with Q chosen to give that product.
  //  - with a temperature grid but no emitter, Stam's form (eqs. 5.1, 5.9): the smoke itself emits
  //    sigma_t rho (1 - Omega) Q with Q = emissionScale * B(T) (emissionScale is Stam's E_lambda),
  //    so an optically thick hot region shows Q (eq. 5.12).
  double emissionScale = 1.0;
  double emissionReference = 1500.0;  // temperature [K] whose black body has unit luminance

  // std::invalid_argument naming the bad value: extinction < 0, albedo outside [0, 1], g outside
  // (-1, 1), emissionScale < 0, emissionReference <= 0, or anything non-finite.
  void validate() const;
};

struct VolumeRenderSettings {
  double stepCells = 0.5;                      // ray-march step in cells (also the shadow-ray step)
  Vec3 background = Vec3(0.02, 0.02, 0.03);    // radiance behind the medium
  Vec3 ambient = Vec3(0.1, 0.1, 0.12);         // sky radiance I_d^0 scattered by the medium (see above)
  double exposure = 1.0;                       // radiance multiplier before tone mapping
  double gamma = 2.2;                          // display gamma of the 8-bit image
  bool toneMap = true;                         // x / (1 + x) per channel; otherwise clamp to [0, 1]
  Vec3 surfaceAlbedo = Vec3::Constant(0.6);    // Lambert albedo of obstacles (surfaceDistance)
  Vec3 meshAlbedo = Vec3::Constant(0.6);       // and of meshes
  Sky sky;                                     // when enabled, what rays leaving the scene see instead of background
  Floor floor;                                 // a floor under the box, when enabled
  LiquidOptics liquid;                         // of VolumeInput::liquid

  // std::invalid_argument for stepCells, exposure or gamma not positive, negative or non-finite
  // background or ambient, a surfaceAlbedo or meshAlbedo outside [0, 1], or an invalid sky, floor or liquid.
  void validate() const;
};

// Cell-centred grids of one layout (std::invalid_argument otherwise).
struct VolumeInput {
  const Grid<float, 3>* density = nullptr;      // required [kg/m^3]
  const Grid<float, 3>* temperature = nullptr;  // optional [K]: emission (see Medium)
  const Grid<float, 3>* emitter = nullptr;      // optional emission weight (e.g. flame density); needs temperature
  const Grid<float, 3>* fluence = nullptr;      // optional multiple-scattering fluence phi [W/m^2], luminance
  // Optional lightTransmittance of each light, in the order of the lights, when the caller has
  // them already (the multiple-scattering source needs them too); computed here otherwise.
  const std::vector<Grid<float, 3>>* transmittances = nullptr;  // (made with the same surfaceDistance)
  // Opaque surfaces: solid obstacles as a signed distance [m] at the cell centres, negative inside
  // (the smoke solver's "obstacle_distance"); triangle meshes; point sets drawn as spheres. Solids
  // of the distance grid shadow the medium and the surfaces through the light grids; meshes and
  // spheres shadow the surfaces by shadow rays but not the medium.
  const Grid<float, 3>* surfaceDistance = nullptr;
  std::vector<const TriangleMesh*> meshes = {};
  std::vector<PointSet> points = {};
  // Optional liquid: a level set at the cell centres [m], negative inside (the liquid solver's
  // "liquid_phi"), drawn as a clear dielectric by liquid_tracer.hpp with settings.liquid.
  const Grid<float, 3>* liquid = nullptr;

  void validate() const;
};

struct RenderStats {
  long long primaryRays = 0;
  long long samples = 0;  // density samples taken by the camera rays (skipped empty bricks not counted)
  long long surfaceHits = 0;  // camera rays (and their reflected and refracted rays) that ended on a surface
  double secondsLightGrids = 0.0, secondsMarch = 0.0;
};

using FloatImage = io::ImageF;  // linear radiance, row-major from the top row, 3 floats per pixel

struct RenderResult {
  FloatImage radiance;  // before exposure and tone mapping
  io::Image image;      // exposure, tone map, gamma, 8 bits
  RenderStats stats;
};

// std::invalid_argument for bad inputs, and (checkCameraOutsideSolids) for a camera inside a solid.
RenderResult renderVolume(const VolumeInput& input, const Camera& camera, const std::vector<Light>& lights,
                          const Medium& medium, const VolumeRenderSettings& settings);

// The signed distance of a cell-centred distance grid at x (trilinear), +infinity outside the
// grid's box (there are no obstacles outside the domain).
double signedDistanceAt(const Grid<float, 3>& distance, const Vec3& x);

// std::invalid_argument "camera is inside an obstacle (signed distance -0.12 m at the camera
// position)" when the distance there is negative, or "camera is inside mesh 2 (a ray from the camera
// crosses it 3 times)" for a closed mesh around it. Nothing can be seen from inside a solid.
void checkCameraOutsideSolids(const Vec3& position, const Grid<float, 3>* surfaceDistance,
                              const std::vector<const TriangleMesh*>& meshes);

// Transmittance T_l(x) = exp(-sigma_t integral rho du) (Beer-Lambert, eq. 5.6) from every cell
// centre to the light, or to where the path leaves the grid's box (there is no medium outside).
// Directional lights: a sweep of slices across the grid from the side facing the light; each cell
// marches its path over 8 slices (at stepCells) and adds the optical depth interpolated bilinearly
// where the path crosses that slice: O(cells), exact where the depth varies linearly across a
// slice (a homogeneous slab), but it blurs sharp shadow edges over a few cells. Point and spot
// lights: the same, with each cell's path across its own dominant axis and the cells done in
// layers outward from the light. The spot's cone does not enter: it is part of E_l.
// With a signed-distance grid of solid obstacles (cell-centred, the density's layout), paths
// through a solid are blocked: T_l is multiplied by the visibility V = clamp(1 + d_min / dx, 0, 1),
// d_min the least distance sampled along the path, so V is 1 on paths that stay outside and 0 on
// those that go a cell deep into a solid (a one-cell soft edge, not a staircase of cells). The sweep
// carries V across slices like the depth, interpolated as a visibility (outside the box V = 1).
Grid<float, 3> lightTransmittance(const Grid<float, 3>& density, const Light& light, const Medium& medium,
                                  double stepCells, const Grid<float, 3>* surfaceDistance = nullptr);

// The first-scatter source of the multiple-scattering problem: the power per unit volume scattered
// out of the reduced incident light, sigma_s rho(x) sum_l Y(E_l(x)) T_l(x) [W/m^3] (Stam's J_ri of
// eq. 5.7 times sigma_t rho, integrated over all directions, where (1/4pi) integral p = 1 leaves
// only the isotropic part), Y the luminance of each light's colour. transmittances[l] belongs to
// lights[l] (from lightTransmittance).
Grid<float, 3> firstScatterSource(const Grid<float, 3>& density, const std::vector<Light>& lights,
                                  const Medium& medium, const std::vector<Grid<float, 3>>& transmittances);

}  // namespace msim::render
