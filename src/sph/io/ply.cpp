#include <sph/io/ply.h>

#include <bit>
#include <cstdint>
#include <cstring>
#include <string>

#include <fmt/format.h>

#include <sph/io/atomic_file.h>

namespace sph {

namespace {

/// Appends `v` in little-endian byte order.
template <class T>
char* put_le(char* p, T v) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  for (std::size_t k = 0; k < sizeof(T); ++k)
    *p++ = static_cast<char>(std::endian::native == std::endian::little ? b[k] : b[sizeof(T) - 1 - k]);
  return p;
}

template <int D, std::floating_point R>
char* put_vec(char* p, const Vec<D, R>& v) {
  for (int d = 0; d < 3; ++d) p = put_le(p, d < D ? static_cast<float>(v[d]) : 0.0f);
  return p;
}

}  // namespace

template <int D, std::floating_point R>
void write_ply(const std::filesystem::path& path, const ParticleSet<D, R>& ps, double time, FrameFieldMask fields) {
  const std::size_t n = ps.size();
  std::string header = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment sph frame\ncomment time {}\nelement vertex {}\n"
      "property float x\nproperty float y\nproperty float z\n",
      time, n);
  std::size_t record = 12;
  if (fields & kFieldVelocity) header += "property float vx\nproperty float vy\nproperty float vz\n", record += 12;
  if (fields & kFieldDensity) header += "property float density\n", record += 4;
  if (fields & kFieldPressure) header += "property float pressure\n", record += 4;
  if (fields & kFieldId) header += "property uint id\n", record += 4;
  if (fields & kFieldInitialPosition)
    header += "property float x0\nproperty float y0\nproperty float z0\n", record += 12;
  header += "end_header\n";
  std::string data(n * record, '\0');
  char* p = data.data();
  for (std::size_t i = 0; i < n; ++i) {
    p = put_vec(p, ps.position[i]);
    if (fields & kFieldVelocity) p = put_vec(p, ps.velocity[i]);
    if (fields & kFieldDensity) p = put_le(p, static_cast<float>(ps.density[i]));
    if (fields & kFieldPressure) p = put_le(p, static_cast<float>(ps.pressure[i]));
    if (fields & kFieldId) p = put_le(p, static_cast<std::uint32_t>(ps.id[i]));  // ids stay below 2e9
    if (fields & kFieldInitialPosition) p = put_vec(p, ps.initial_position[i]);
  }
  AtomicFile f(path);
  f.write(header);
  f.write(data);
  f.commit();
}

#define SPH_INSTANTIATE(D, R) \
  template void write_ply<D, R>(const std::filesystem::path&, const ParticleSet<D, R>&, double, FrameFieldMask);
SPH_INSTANTIATE(2, float)
SPH_INSTANTIATE(2, double)
SPH_INSTANTIATE(3, float)
SPH_INSTANTIATE(3, double)
#undef SPH_INSTANTIATE

}  // namespace sph
