#include <sph/io/checkpoint.h>

#include <array>
#include <cstring>

#include <fmt/format.h>

#include <sph/core/error.h>
#include <sph/core/state_stream.h>
#include <sph/core/version.h>
#include <sph/io/atomic_file.h>
#include <sph/scene/scene_writer.h>

namespace sph {

namespace fs = std::filesystem;

namespace {

constexpr std::array<char, 8> kMagic{'S', 'P', 'H', 'C', 'K', 'P', 'T', '\0'};
constexpr std::array<char, 8> kEndMagic{'S', 'P', 'H', 'C', 'K', 'E', 'N', 'D'};
constexpr std::uint32_t kByteOrderMark = 0x01020304;
constexpr std::uint64_t kHeaderBytes = 16, kTrailerBytes = 24;

}  // namespace

template <int D, std::floating_point R>
void write_checkpoint(const fs::path& dir, const SceneDesc& desc, const Simulation<D, R>& sim, RunOutput<D, R>& output,
                      double wall_seconds, std::int64_t checkpoint_every) {
  AtomicFile file(dir / kCheckpointFile);
  std::ofstream& os = file.stream();
  os.write(kMagic.data(), kMagic.size());
  os.write(reinterpret_cast<const char*>(&kCheckpointVersion), sizeof kCheckpointVersion);
  os.write(reinterpret_cast<const char*>(&kByteOrderMark), sizeof kByteOrderMark);

  StateWriter w(os);
  w.put(std::string(kVersion));
  w.put(static_cast<std::uint8_t>(D));
  w.put(static_cast<std::uint8_t>(std::is_same_v<R, float> ? 0 : 1));
  w.put(sim.steps_done());
  w.put(scene_text(desc));
  w.put(desc.source);
  w.put(static_cast<std::uint8_t>(sim.params().audit));
  w.put(checkpoint_every);
  w.put(output.identity().run_id);
  w.put(output.identity().scene_fingerprint);
  sim.save_state(w);
  output.save_state(w, sim, wall_seconds);

  const std::uint64_t length = w.written(), sum = w.checksum().value();
  os.write(reinterpret_cast<const char*>(&length), sizeof length);
  os.write(reinterpret_cast<const char*>(&sum), sizeof sum);
  os.write(kEndMagic.data(), kEndMagic.size());
  file.commit(/*sync=*/true);
}

CheckpointReader::CheckpointReader(fs::path file) : file_(std::move(file)) {
  const std::string where = file_.string();
  std::error_code ec;
  if (!fs::exists(file_, ec))
    throw Error(
        "no checkpoint here; a run writes one with --checkpoint-every N, or when it is interrupted "
        "(Ctrl-C, SIGTERM)",
        where);
  if (!fs::is_regular_file(file_, ec)) throw Error("is not a file; expected a checkpoint file", where);
  const std::uint64_t size = fs::file_size(file_, ec);
  in_.open(file_, std::ios::binary);
  if (ec || !in_) throw Error("cannot read the checkpoint (permissions?)", where);

  std::array<char, 8> magic{};
  in_.read(magic.data(), magic.size());
  if (!in_ || magic != kMagic) throw Error("is not an sph checkpoint (it does not start with SPHCKPT)", where);
  std::uint32_t version = 0, bom = 0;
  in_.read(reinterpret_cast<char*>(&version), sizeof version);
  in_.read(reinterpret_cast<char*>(&bom), sizeof bom);
  if (!in_ || size < kHeaderBytes + kTrailerBytes)
    throw Error("the checkpoint is truncated (it ends inside its header); it cannot be resumed", where);
  if (bom != kByteOrderMark)
    throw Error("the checkpoint was written on a machine with another byte order; it cannot be resumed here", where);
  if (version != kCheckpointVersion)
    throw Error(fmt::format("the checkpoint has format version {}; this sph ({}) reads version {} only{}", version,
                            kVersion, kCheckpointVersion,
                            version < kCheckpointVersion
                                ? ": it was written by an older sph; finish the run with that version, or start it "
                                  "again with this one"
                                : ""),
                where);

  // Trailer: the length must account for the whole file and the checksum must match.
  std::array<char, 8> end_magic{};
  in_.seekg(static_cast<std::streamoff>(size - kTrailerBytes));
  in_.read(reinterpret_cast<char*>(&payload_), sizeof payload_);
  in_.read(reinterpret_cast<char*>(&checksum_), sizeof checksum_);
  in_.read(end_magic.data(), end_magic.size());
  if (!in_ || end_magic != kEndMagic || payload_ != size - kHeaderBytes - kTrailerBytes)
    throw Error(
        "the checkpoint is truncated or was cut short while written (its end marker is missing); it cannot "
        "be resumed",
        where);
  in_.seekg(static_cast<std::streamoff>(kHeaderBytes));
  {
    Checksum sum;
    std::vector<char> block(std::size_t{1} << 20);
    for (std::uint64_t left = payload_; left > 0;) {
      const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(left, block.size()));
      in_.read(block.data(), static_cast<std::streamsize>(n));
      if (static_cast<std::size_t>(in_.gcount()) != n) throw Error("the checkpoint could not be read whole", where);
      sum.add(block.data(), n);
      left -= n;
    }
    if (sum.value() != checksum_)
      throw Error("the checkpoint's checksum does not match its contents: the file is corrupt; it cannot be resumed",
                  where);
  }

  in_.seekg(static_cast<std::streamoff>(kHeaderBytes));
  reader_ = std::make_unique<StateReader>(in_, payload_, where);
  reader_->get(header_.sph_version);
  header_.dimension = reader_->get<std::uint8_t>();
  const auto precision = reader_->get<std::uint8_t>();
  reader_->get(header_.step);
  reader_->get(header_.scene_json);
  reader_->get(header_.scene_source);
  header_.audit = reader_->get<std::uint8_t>() != 0;
  reader_->get(header_.checkpoint_every);
  reader_->get(header_.identity.run_id);
  reader_->get(header_.identity.scene_fingerprint);
  reader_->expect(header_.dimension == 2 || header_.dimension == 3, "a dimension other than 2 or 3");
  reader_->expect(precision <= 1, "an unknown precision");
  reader_->expect(header_.step >= 0, "a negative step");
  reader_->expect(header_.checkpoint_every >= 0, "a negative checkpoint interval");
  reader_->expect(!header_.identity.run_id.empty(), "no run id");
  header_.precision = precision == 0 ? Precision::Float : Precision::Double;
}

CheckpointReader::~CheckpointReader() = default;

template <int D, std::floating_point R>
std::string CheckpointReader::restore(Simulation<D, R>& sim, RunOutput<D, R>& output) {
  constexpr bool is_float = std::is_same_v<R, float>;
  SPH_CHECK(header_.dimension == D && (header_.precision == Precision::Float) == is_float,
            "checkpoint restored into a simulation of another dimension or precision");
  sim.load_state(*reader_);
  reader_->expect(sim.steps_done() == header_.step, "the state's step differs from the header's");
  std::string warning = output.resume(sim, *reader_);
  reader_->expect(reader_->left() == 0, "bytes left over after the state");
  return warning;
}

#define SPH_CHECKPOINT_INSTANTIATE(D, R)                                                                             \
  template void write_checkpoint<D, R>(const fs::path&, const SceneDesc&, const Simulation<D, R>&, RunOutput<D, R>&, \
                                       double, std::int64_t);                                                        \
  template std::string CheckpointReader::restore<D, R>(Simulation<D, R>&, RunOutput<D, R>&);
SPH_CHECKPOINT_INSTANTIATE(2, float)
SPH_CHECKPOINT_INSTANTIATE(2, double)
SPH_CHECKPOINT_INSTANTIATE(3, float)
SPH_CHECKPOINT_INSTANTIATE(3, double)
#undef SPH_CHECKPOINT_INSTANTIATE

}  // namespace sph
