#pragma once
// Internal to the simulator's hard contact (sim_contact.cpp, sim_contact_modes.cpp;
// docs/model.md section 11): what the event step and the choice of contact modes share.
#include <vector>

#include "sim_run_state.hpp"

namespace abuopt::detail {

constexpr double kGapTol = 1e-9;  // rad: a pair this close counts as touching

// Rebuilds the clusters from cs.closed, walking the cyclic order from just after an open pair.
void build_clusters(RunState& rs);
// The size of the forces on cluster g (sum of mbar_i (mu |fn_i| + |fw_i| + |hb_i|)), for
// relative tolerances.
double group_scale(const RunState& rs, const std::vector<std::size_t>& g);

}  // namespace abuopt::detail
