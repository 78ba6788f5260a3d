// Stage kind `local`: a polish (COBYLA, BOBYQA, SLSQP, ...) on every choice, starting from the best
// design so far (the family's starting point when it is the first stage).
#include "study_context.hpp"

namespace abuopt::studies::detail {

void run_local_stage(StudyContext& c, const StageSpec& stage) { run_optimiser_stage(c, stage, true); }

}  // namespace abuopt::studies::detail
