// Stage kind `global`: an optimiser of the registry (DIRECT_L, CRS2_LM, ISRES, ESCH, SAO, or any
// other) on every choice, from the family's starting point. An optimiser that takes bounds only
// sees the problem in exact-penalty form (stage key penalty_weight); the stage's best design is
// the best one that meets the real constraints.
#include "study_context.hpp"

namespace abuopt::studies::detail {

void run_global_stage(StudyContext& c, const StageSpec& stage) { run_optimiser_stage(c, stage, false); }

}  // namespace abuopt::studies::detail
