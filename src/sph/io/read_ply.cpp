#include <sph/io/frame_source.h>

#include <algorithm>
#include <array>
#include <sstream>

#include <fmt/format.h>

namespace sph::detail {

namespace {

struct Prop {
  std::string name;
  Num type;
};

/// Reads the PLY header into `b` (time, vertex count) and returns the vertex properties in
/// order and, in `data`, where the vertex records start.
std::vector<Prop> read_ply_header(const Source& src, FrameBuilder& b, std::size_t& data) {
  const std::string& f = src.bytes;
  const std::string end_marker = "end_header\n";
  if (f.rfind("ply\n", 0) != 0) src.fail("is not a PLY file (it does not start with \"ply\")");
  const std::size_t he = f.find(end_marker);
  if (he == std::string::npos) src.fail("its PLY header has no end_header line: the file is truncated or corrupt");
  std::istringstream header(f.substr(4, he - 4));
  bool have_format = false, have_vertex = false;
  std::vector<Prop> props;
  for (std::string line; std::getline(header, line);) {
    const auto w = split(line);
    if (w.empty()) continue;
    if (w[0] == "format") {
      if (w.size() != 3 || w[1] != "binary_little_endian" || w[2] != "1.0")
        src.fail("is not a binary little-endian PLY file, as sph writes them");
      have_format = true;
    } else if (w[0] == "comment" || w[0] == "obj_info") {
      if (w.size() >= 3 && w[1] == "time") {
        const auto t = parse_real(w[2]);
        if (!t) src.fail("its \"comment time\" is not a finite number");
        b.data.time = *t;
      }
    } else if (w[0] == "element") {
      if (have_vertex || w.size() != 3 || w[1] != "vertex")
        src.fail("has an element other than one \"element vertex N\": not a PLY file as sph writes it");
      const auto n = parse_count(w[2]);
      if (!n) src.fail("bad vertex count in its PLY header");
      b.set_size(*n, 1);
      have_vertex = true;
    } else if (w[0] == "property") {
      if (!have_vertex || w.size() != 3) src.fail("has a property that is not a scalar vertex property");
      Num t;
      if (w[1] == "float" || w[1] == "float32")
        t = Num::F32;
      else if (w[1] == "double" || w[1] == "float64")
        t = Num::F64;
      else if (w[1] == "uint" || w[1] == "uint32")
        t = Num::U32;
      else if (w[1] == "int" || w[1] == "int32")
        t = Num::I32;
      else
        src.fail("has a property of type \"" + std::string(w[1]) + "\", which sph does not write");
      for (const Prop& p : props)
        if (p.name == w[2]) src.fail("has the property \"" + p.name + "\" twice");
      props.push_back({std::string(w[2]), t});
    } else {
      src.fail("has an unexpected PLY header line \"" + line.substr(0, 40) + "\"");
    }
  }
  if (!have_format || !have_vertex) src.fail("has no format or no vertex element in its PLY header");
  data = he + end_marker.size();
  return props;
}

}  // namespace

FrameData read_ply(const Source& src) {
  const std::string& f = src.bytes;
  FrameBuilder b(src);
  std::size_t data = 0;
  const std::vector<Prop> props = read_ply_header(src, b, data);
  std::size_t record = 0;
  for (const Prop& p : props) record += num_size(p.type);
  const std::size_t n = b.data.size;
  if (record == 0 || (f.size() - data) / record != n || (f.size() - data) % record != 0)
    src.fail(fmt::format("holds {} bytes of vertex data; expected {} for {} vertices: the file is truncated or corrupt",
                         f.size() - data, static_cast<std::uint64_t>(record) * n, n));
  // Which field (and component) each property fills: the position's x y z, the PLY names of
  // each field frames hold (kParticleFields), and for a field the run added NAME (a real) or
  // NAME_x, NAME_y, NAME_z (a vector), as ParticleSet names them.
  struct Group {
    std::string name;  // "" for the position
    int components;
    std::array<bool, 3> seen{};
    std::vector<double> values;
  };
  std::vector<Group> groups{{"", 3, {}, {}}};
  struct Target {
    std::size_t group;
    int component;
  };
  const auto group = [&](std::string_view name, int components) {
    for (std::size_t g = 1; g < groups.size(); ++g)
      if (groups[g].name == name) return g;
    groups.push_back({std::string(name), components, {}, {}});
    return groups.size() - 1;
  };
  const auto target_of = [&](const std::string& prop) -> Target {
    for (int c = 0; c < 3; ++c)
      if (prop == kParticleFields[field::kPosition].ply[static_cast<std::size_t>(c)]) return {0, c};
    for (const FieldDesc& fd : kParticleFields)
      for (int c = 0; fd.in_frames && c < fd.components(); ++c)
        if (prop == fd.ply[static_cast<std::size_t>(c)]) return {group(fd.name, fd.components()), c};
    for (const FieldSpec& a : src.added) {
      if (find_particle_field(a.name)) continue;
      const std::array<std::string, 3> names = added_field_ply_names(a);
      const int components = a.kind == FieldKind::Vector ? 3 : 1;
      for (int c = 0; c < components; ++c)
        if (prop == names[static_cast<std::size_t>(c)]) return {group(a.name, components), c};
    }
    src.fail("has the vertex property \"" + prop + "\", which sph does not write");
  };
  std::vector<Target> targets;
  for (const Prop& p : props) {
    targets.push_back(target_of(p.name));
    groups[targets.back().group].seen[static_cast<std::size_t>(targets.back().component)] = true;
  }
  for (Group& g : groups) {
    const int count = static_cast<int>(std::count(g.seen.begin(), g.seen.end(), true));
    if (g.name.empty() && count == 0) src.fail("does not hold x, y and z");
    if (count != g.components)
      src.fail(g.name.empty() ? "does not hold all of x, y and z" : "holds only some of the components of " + g.name);
    g.values.resize(n * static_cast<std::size_t>(g.components));
  }
  const char* p = f.data() + data;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = 0; k < props.size(); ++k) {
      Group& g = groups[targets[k].group];
      g.values[i * static_cast<std::size_t>(g.components) + static_cast<std::size_t>(targets[k].component)] =
          load(p, props[k].type, /*big=*/false);
      p += num_size(props[k].type);
    }
  b.data.position = std::move(groups[0].values);
  for (std::size_t g = 1; g < groups.size(); ++g)
    b.add(groups[g].name, groups[g].components, std::move(groups[g].values));
  return b.finish(true);
}

}  // namespace sph::detail
