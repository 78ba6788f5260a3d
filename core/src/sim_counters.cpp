#include "abuopt/core/sim_counters.hpp"

namespace abuopt {

SimCounters& sim_counters() {
  thread_local SimCounters c;
  return c;
}

}  // namespace abuopt
