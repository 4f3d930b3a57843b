#include <sph/core/error.h>
#include <sph/core/parallel.h>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace sph {

void set_num_threads(int n) {
  SPH_CHECK(n >= 1, "thread count must be positive");
#ifdef _OPENMP
  omp_set_num_threads(n);
#endif
}

int num_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

int thread_index() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

}  // namespace sph
