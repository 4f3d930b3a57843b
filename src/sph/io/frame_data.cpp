#include <sph/io/frames.h>

#include <type_traits>

namespace sph {

template <int D, std::floating_point R>
FrameData frame_data_of(const ParticleSet<D, R>& ps, double time, const FrameFields& fields) {
  const std::size_t n = ps.size();
  FrameData out;
  out.time = time;
  out.size = n;
  out.position.assign(3 * n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (int d = 0; d < D; ++d)
      out.position[3 * i + static_cast<std::size_t>(d)] = static_cast<double>(ps.position[i][d]);
  for_each_frame_field(ps, fields, [&](const FieldDesc& f, const auto& column) {
    FrameField ff{std::string(f.name), f.components(),
                  std::vector<double>(n * static_cast<std::size_t>(f.components()))};
    for (std::size_t i = 0; i < n; ++i) {
      using T = typename std::decay_t<decltype(column)>::value_type;
      if constexpr (std::is_same_v<T, Vec<D, R>>) {
        for (int d = 0; d < D; ++d) ff.values[3 * i + static_cast<std::size_t>(d)] = static_cast<double>(column[i][d]);
      } else {
        ff.values[i] = static_cast<double>(column[i]);
      }
    }
    out.fields.push_back(std::move(ff));
  });
  return out;
}

#define SPH_INSTANTIATE(D, R) \
  template FrameData frame_data_of<D, R>(const ParticleSet<D, R>&, double, const FrameFields&);
SPH_INSTANTIATE(2, float)
SPH_INSTANTIATE(2, double)
SPH_INSTANTIATE(3, float)
SPH_INSTANTIATE(3, double)
#undef SPH_INSTANTIATE

}  // namespace sph
