#pragma once
/// \file Internals shared by the frame readers (read_vtu.cpp, read_vtk.cpp, read_ply.cpp): the file
/// in memory, number decoding, and FrameBuilder, which checks each point field against the
/// particle-field table.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <sph/core/error.h>
#include <sph/io/frames.h>

namespace sph::detail {

/// The number types frames hold.
enum class Num { F32, F64, U8, U32, I32, U64, I64 };

std::size_t num_size(Num t);
/// The value of type `t` at `p`, stored big- or little-endian, as a double.
double load(const char* p, Num t, bool big);

/// A whole file in memory, and the error every reader throws: naming the file.
struct Source {
  std::filesystem::path path;
  std::string bytes;
  std::span<const FieldSpec> added;  ///< the fields the run added, which the file may hold too

  [[noreturn]] void fail(const std::string& message) const { throw Error(message, path.string()); }
};

/// A whole unsigned decimal number, or nullopt.
std::optional<std::uint64_t> parse_count(std::string_view s);
/// A whole finite decimal number, or nullopt.
std::optional<double> parse_real(std::string_view s);
/// The words of a line, split at spaces, tabs and carriage returns.
std::vector<std::string_view> split(std::string_view line);

/// Collects the fields of a frame and checks names, sizes and duplicates. A point field is one of
/// kParticleFields that frames hold or one of the source's `added` fields, with its components.
class FrameBuilder {
 public:
  explicit FrameBuilder(const Source& src) : src_(src) {}
  FrameData data;

  /// Checks that a point count is plausible for the file's size before anything is allocated
  /// for it (`min_bytes` per point at least).
  void set_size(std::uint64_t n, std::size_t min_bytes);
  void add(const std::string& name, int components, std::vector<double> values);
  /// The frame, its fields in the particle set's field order (built-in ones in table order, then
  /// added ones in their order).
  FrameData finish(bool have_position);

 private:
  const Source& src_;
};

/// The added field of this name, or nullptr.
const FieldSpec* find_added(std::span<const FieldSpec> added, std::string_view name);

FrameData read_vtu(const Source& src);
FrameData read_legacy_vtk(const Source& src);
FrameData read_ply(const Source& src);

}  // namespace sph::detail
