// The validation's measures on plain data (validation.h): the Martin & Moyce (1952) front and
// its error, energies, the hydrostatic profile, settling, the lattice's gradient consistency.

#include <sph/analysis/validation.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/core/kernels.h>
#include <sph/core/vec.h>
#include <sph/solver/wcsph.h>

namespace sph {

namespace {

// Martin & Moyce (1952), Table 2, n^2 = 2: (T, Z), the initial condition first.
constexpr std::array<FrontPoint, 16> kMartinMoyce{{{0.00, 1.00},
                                                   {0.41, 1.11},
                                                   {0.84, 1.22},
                                                   {1.19, 1.44},
                                                   {1.43, 1.67},
                                                   {1.63, 1.89},
                                                   {1.83, 2.11},
                                                   {1.98, 2.33},
                                                   {2.20, 2.56},
                                                   {2.32, 2.78},
                                                   {2.51, 3.00},
                                                   {2.65, 3.22},
                                                   {2.83, 3.44},
                                                   {2.98, 3.67},
                                                   {3.11, 3.89},
                                                   {3.33, 4.11}}};

}  // namespace

std::span<const FrontPoint> martin_moyce_1952() { return kMartinMoyce; }

double martin_moyce_time(double t, double g, double a) { return t * std::sqrt(2.0 * g / a); }

double surge_front(std::span<const double> x, std::span<const double> y, double floor, double spacing, double h,
                   int min_neighbors) {
  if (x.size() != y.size()) throw Error(fmt::format("{} x values but {} y values", x.size(), y.size()), "surge_front");
  const double band = floor + 2.0 * spacing;
  // Candidate neighbors of floor particles lie below band + h; bin them by x in cells of h, so
  // that a floor particle looks at three cells instead of every particle.
  std::vector<std::pair<std::int64_t, std::size_t>> cells;
  std::vector<std::size_t> on_floor;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) continue;
    if (y[i] < band + h) cells.emplace_back(static_cast<std::int64_t>(std::floor(x[i] / h)), i);
    if (y[i] < band) on_floor.push_back(i);
  }
  std::sort(cells.begin(), cells.end());
  // Farthest first: the first floor particle with enough neighbors is the front.
  std::sort(on_floor.begin(), on_floor.end(), [&](std::size_t a, std::size_t b) { return x[a] > x[b]; });
  const double h2 = h * h;
  for (std::size_t i : on_floor) {
    const std::int64_t c = static_cast<std::int64_t>(std::floor(x[i] / h));
    int count = 0;
    for (std::int64_t cc = c - 1; cc <= c + 1 && count < min_neighbors; ++cc) {
      auto it = std::lower_bound(cells.begin(), cells.end(), std::make_pair(cc, std::size_t{0}));
      for (; it != cells.end() && it->first == cc && count < min_neighbors; ++it) {
        const std::size_t j = it->second;
        if (j == i) continue;
        const double dx = x[i] - x[j], dy = y[i] - y[j];
        if (dx * dx + dy * dy < h2) ++count;
      }
    }
    if (count >= min_neighbors) return x[i] + 0.5 * spacing;
  }
  return kNaN;
}

double interpolate(std::span<const double> xs, std::span<const double> ys, double x) {
  if (xs.size() != ys.size())
    throw Error(fmt::format("{} x values but {} y values", xs.size(), ys.size()), "interpolate");
  if (xs.empty() || !(x >= xs.front()) || !(x <= xs.back())) return kNaN;
  const auto it = std::lower_bound(xs.begin(), xs.end(), x);
  const std::size_t k = static_cast<std::size_t>(it - xs.begin());
  if (xs[k] == x) return ys[k];
  const double x0 = xs[k - 1], x1 = xs[k];
  const double w = (x - x0) / (x1 - x0);
  return ys[k - 1] + w * (ys[k] - ys[k - 1]);
}

FrontError front_error(std::span<const double> T, std::span<const double> Z, std::span<const FrontPoint> experiment,
                       double t_max, double t_min) {
  FrontError e;
  double sum = 0, sum2 = 0, worst = -1;
  for (const FrontPoint& p : experiment) {
    if (!(p.T > t_min) || p.T > t_max) continue;
    const double z = interpolate(T, Z, p.T);
    e.experiment.push_back(p);
    e.simulated.push_back(z);
    if (!std::isfinite(z)) {
      e.complete = false;
      continue;
    }
    const double d = z - p.Z;
    ++e.points;
    sum += d;
    sum2 += d * d;
    if (std::abs(d) > worst) worst = std::abs(d), e.worst_T = p.T;
  }
  if (e.points > 0) {
    e.max = worst;
    e.mean = sum / e.points;
    e.rms = std::sqrt(sum2 / e.points);
  }
  if (e.experiment.empty()) e.complete = false;
  return e;
}

FrontError front_change(std::span<const double> fine_T, std::span<const double> fine_Z,
                        std::span<const double> coarse_T, std::span<const double> coarse_Z, const FrontError& at) {
  std::vector<FrontPoint> coarse;
  bool complete = true;
  for (const FrontPoint& p : at.experiment) {
    const double z = interpolate(coarse_T, coarse_Z, p.T);
    if (std::isfinite(z))
      coarse.push_back({p.T, z});
    else
      complete = false;
  }
  FrontError e = front_error(fine_T, fine_Z, coarse, std::numeric_limits<double>::infinity());
  e.complete = e.complete && complete;
  return e;
}

double eos_internal_energy(double rho, double rho0, double stiffness) {
  if (!(rho > rho0)) return 0.0;
  return stiffness * (std::log(rho / rho0) + rho0 / rho - 1.0);
}

EnergyParts energy(const FluidState& s, const EnergyModel& m) {
  EnergyParts e;
  const double mass = s.particle_mass;
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    const auto& x = s.position[i];
    const auto& v = s.velocity[i];
    e.kinetic += 0.5 * mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    e.potential += mass * m.gravity * (x[1] - m.box_lo[1]);
    if (i < s.density.size()) e.internal += mass * eos_internal_energy(s.density[i], m.rest_density, m.stiffness);
    if (m.wall_stiffness > 0) {
      double d2 = 0;
      for (int d = 0; d < s.dimension; ++d) {
        const double lo = m.box_lo[d] + m.particle_radius - x[d];
        const double hi = x[d] - (m.box_hi[d] - m.particle_radius);
        if (lo > 0) d2 += lo * lo;
        if (hi > 0) d2 += hi * hi;
      }
      e.wall += 0.5 * mass * m.wall_stiffness * d2;
    }
  }
  return e;
}

double largest_rise(std::span<const double> values) {
  double rise = 0, low = std::numeric_limits<double>::infinity();
  for (double v : values) {
    if (!std::isfinite(v)) continue;
    low = std::min(low, v);
    rise = std::max(rise, v - low);
  }
  return rise;
}

double free_surface_height(const FluidState& s, double spacing) {
  // Top particle of each column; columns are keyed by their integer cell indices.
  std::map<std::pair<std::int64_t, std::int64_t>, double> top;
  for (const auto& x : s.position) {
    const std::int64_t cx = static_cast<std::int64_t>(std::floor(x[0] / spacing));
    const std::int64_t cz = s.dimension == 3 ? static_cast<std::int64_t>(std::floor(x[2] / spacing)) : 0;
    auto [it, added] = top.try_emplace({cx, cz}, x[1]);
    if (!added) it->second = std::max(it->second, x[1]);
  }
  if (top.empty()) return kNaN;
  double sum = 0;
  for (const auto& [k, y] : top) sum += y;
  return sum / static_cast<double>(top.size()) + 0.5 * spacing;
}

HydrostaticProfile hydrostatic_profile(const FluidState& s, const HydrostaticModel& m) {
  SPH_CHECK(m.spacing > 0 && m.h > 0 && m.bin_layers > 0, "hydrostatic_profile needs a spacing, h and bin width");
  HydrostaticProfile p;
  p.surface = free_surface_height(s, m.spacing);
  const double rho_g = m.rest_density * m.gravity;
  const double bin = m.bin_layers * m.spacing;
  const double top = m.skip_layers * m.spacing;
  std::map<std::int64_t, DepthBin> bins, layers;  // bins of `bin`, and of one spacing (the layers)
  double ratio_sum = 0;
  p.interior_density_min = std::numeric_limits<double>::infinity();
  p.interior_density_max = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    const auto& x = s.position[i];
    const double rel = (s.density[i] - m.rest_density) / m.rest_density;
    p.max_compression = std::max(p.max_compression, rel);
    const double depth = p.surface - x[1];
    if (!(depth > top)) continue;
    const double margin = m.wall_margin < 0 ? m.h : m.wall_margin;
    bool interior = x[1] - m.box_lo[1] > margin;
    for (int d = 0; d < s.dimension; ++d)
      if (d != 1) interior = interior && x[d] - m.box_lo[d] > margin && m.box_hi[d] - x[d] > margin;
    if (!interior) continue;
    ++p.particles;
    ratio_sum += s.pressure[i] / (rho_g * depth);
    p.mean_density_error += std::abs(rel);
    p.interior_density_min = std::min(p.interior_density_min, rel);
    p.interior_density_max = std::max(p.interior_density_max, rel);
    for (auto [width, into] : {std::pair{bin, &bins}, std::pair{m.spacing, &layers}}) {
      DepthBin& b = (*into)[static_cast<std::int64_t>(std::floor((depth - top) / width))];
      b.depth += depth;
      b.pressure += s.pressure[i];
      ++b.count;
    }
  }
  if (p.particles == 0) {
    p.interior_density_min = p.interior_density_max = p.mean_density_error = kNaN;
    p.mean_ratio = kNaN;
    p.max_bin_error = p.max_layer_error = kNaN;
    return p;
  }
  p.mean_ratio = ratio_sum / static_cast<double>(p.particles);
  p.mean_density_error /= static_cast<double>(p.particles);
  // The deepest bin is cut by the floor's margin and holds a few particles at its top: such a
  // bin (fewer than half the median count) is noise, not a profile, and is not compared.
  const auto compare = [&](std::map<std::int64_t, DepthBin>& of, std::vector<DepthBin>* keep) {
    std::vector<std::size_t> counts;
    for (const auto& [k, b] : of) counts.push_back(b.count);
    std::nth_element(counts.begin(), counts.begin() + counts.size() / 2, counts.end());
    const std::size_t min_count = std::max<std::size_t>(3, counts[counts.size() / 2] / 2);
    double worst = 0;
    for (auto& [k, b] : of) {
      b.depth /= static_cast<double>(b.count);
      b.pressure /= static_cast<double>(b.count);
      b.ratio = b.pressure / (rho_g * b.depth);
      b.compared = b.count >= min_count;
      if (b.compared) worst = std::max(worst, std::abs(b.ratio - 1.0));
      if (keep) keep->push_back(b);
    }
    return worst;
  };
  p.max_bin_error = compare(bins, &p.bins);
  p.max_layer_error = compare(layers, nullptr);
  return p;
}

double settling_time(std::span<const double> times, std::span<const double> values, double fraction) {
  SPH_CHECK(times.size() == values.size(), "settling_time: one value per time");
  if (values.empty()) return kNaN;
  const double peak = *std::max_element(values.begin(), values.end());
  std::size_t last_above = values.size();
  for (std::size_t i = 0; i < values.size(); ++i)
    if (values[i] > fraction * peak) last_above = i;
  if (last_above == values.size()) return times.front();
  if (last_above + 1 == values.size()) return kNaN;
  return times[last_above + 1];
}

namespace {
/// M_yy of lattice_gradient_consistency in D dimensions.
template <int D>
double lattice_m_yy(double spacing, double h, bool poly6_gradient) {
  const double volume = lattice_mass<D>(1.0, spacing, h);  // m / rho0 with rho0 = 1
  const Poly6Kernel<D, double> poly6(h);
  const SpikyKernel<D, double> spiky(h);
  const int n = static_cast<int>(std::ceil(h / spacing)) + 1;
  double sum = 0;
  for (int a = -n; a <= n; ++a)
    for (int b = -n; b <= n; ++b)
      for (int c = (D == 3 ? -n : 0); c <= (D == 3 ? n : 0); ++c) {
        // x_i at the origin and x_j on the lattice: rij = x_i - x_j; the term is -V_j y_ij dW/dy_i.
        Vec<D, double> rij{};
        rij[0] = -a * spacing;
        rij[1] = -b * spacing;
        if constexpr (D == 3) rij[2] = -c * spacing;
        const double r2 = norm2(rij);
        if (!(r2 > 0)) continue;
        const Vec<D, double> g = poly6_gradient ? poly6.gradient(rij, r2) : spiky.gradient(rij, std::sqrt(r2));
        sum -= volume * rij[1] * g[1];
      }
  return sum;
}
}  // namespace

double lattice_gradient_consistency(int dimension, double spacing, double h, bool poly6_gradient) {
  if (dimension != 2 && dimension != 3) throw Error("expected 2 or 3", "dimension");
  return dimension == 2 ? lattice_m_yy<2>(spacing, h, poly6_gradient) : lattice_m_yy<3>(spacing, h, poly6_gradient);
}

}  // namespace sph
