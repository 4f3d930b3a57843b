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

template <int D, std::floating_point R>
char* put_value(char* p, const Vec<D, R>& v) {
  return put_vec(p, v);
}
template <std::floating_point R>
char* put_value(char* p, R v) {
  return put_le(p, static_cast<float>(v));
}
char* put_value(char* p, std::uint32_t id) { return put_le(p, id); }

}  // namespace

template <int D, std::floating_point R>
void write_ply(const std::filesystem::path& path, const ParticleSet<D, R>& ps, double time, const FrameFields& fields) {
  const std::size_t n = ps.size();
  std::string header = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment sph frame\ncomment time {}\nelement vertex {}\n"
      "property float x\nproperty float y\nproperty float z\n",
      time, n);
  std::size_t record = 12;
  for_each_frame_field(ps, fields, [&](const FieldDesc& f, const auto&) {
    const char* type = f.kind == FieldKind::Id ? "uint" : "float";  // ids stay below 2e9
    for (int c = 0; c < f.components(); ++c) header += fmt::format("property {} {}\n", type, f.ply[c]);
    record += 4 * static_cast<std::size_t>(f.components());
  });
  header += "end_header\n";
  // Field by field into the interleaved records: each field's values at its offset in a record.
  std::string data(n * record, '\0');
  for (std::size_t i = 0; i < n; ++i) put_vec(data.data() + i * record, ps.position[i]);
  std::size_t offset = 12;
  for_each_frame_field(ps, fields, [&](const FieldDesc& f, const auto& column) {
    for (std::size_t i = 0; i < n; ++i) put_value(data.data() + i * record + offset, column[i]);
    offset += 4 * static_cast<std::size_t>(f.components());
  });
  AtomicFile f(path);
  f.write(header);
  f.write(data);
  f.commit();
}

#define SPH_INSTANTIATE(D, R) \
  template void write_ply<D, R>(const std::filesystem::path&, const ParticleSet<D, R>&, double, const FrameFields&);
SPH_INSTANTIATE(2, float)
SPH_INSTANTIATE(2, double)
SPH_INSTANTIATE(3, float)
SPH_INSTANTIATE(3, double)
#undef SPH_INSTANTIATE

}  // namespace sph
