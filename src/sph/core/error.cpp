#include <sph/core/error.h>

namespace sph::detail {

void check_failed(const char* expr, const char* file, int line, const std::string& msg) {
  throw std::logic_error(std::string("internal error (please report): check `") + expr + "` failed at " + file + ":" +
                         std::to_string(line) + (msg.empty() ? std::string() : ": " + msg));
}

}  // namespace sph::detail
