#include <sph/core/state_stream.h>

#include <sph/core/error.h>

namespace sph {

namespace {
std::uint64_t load_word(const unsigned char* p) {
  std::uint64_t w = 0;
  for (int k = 7; k >= 0; --k) w = (w << 8) | p[k];  // little-endian word whatever the machine
  return w;
}
}  // namespace

void Checksum::add(const void* data, std::size_t size) {
  const auto* p = static_cast<const unsigned char*>(data);
  bytes_ += size;
  while (size > 0 && npending_ > 0 && npending_ < 8) {  // complete a word started by an earlier call
    pending_[npending_++] = *p++;
    --size;
    if (npending_ == 8) {
      mix(load_word(pending_));
      npending_ = 0;
    }
  }
  if (size == 0) return;
  // Here no word is pending (the loop above completed it, or there was none).
  for (; size >= 8; size -= 8, p += 8) mix(load_word(p));
  for (std::size_t k = 0; k < size; ++k) pending_[k] = p[k];
  npending_ = size;
}

std::uint64_t Checksum::value() const {
  Checksum c = *this;
  unsigned char tail[8] = {};
  for (std::size_t k = 0; k < c.npending_; ++k) tail[k] = c.pending_[k];
  if (c.npending_ > 0) c.mix(load_word(tail));
  c.mix(c.bytes_);  // the length, so that trailing zero bytes are not lost
  return c.h_;
}

void StateReader::bytes(void* data, std::size_t size) {
  if (size > left_) fail("it ends early");
  in_.read(static_cast<char*>(data), static_cast<std::streamsize>(size));
  if (static_cast<std::size_t>(in_.gcount()) != size) fail("it ends early");
  left_ -= size;
  sum_.add(data, size);
}

std::size_t StateReader::count(std::size_t element_size) {
  const auto n = get<std::uint64_t>();
  if (element_size > 0 && n > left_ / element_size) fail("a length field is larger than the file");
  return static_cast<std::size_t>(n);
}

void StateReader::fail(const std::string& what) const {
  throw Error("the checkpoint is corrupt or truncated (" + what + "); it cannot be resumed", source_);
}

}  // namespace sph
