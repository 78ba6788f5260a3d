// Stage kind `replicate`: the best design of every choice on fresh samples (one per seed: other
// initial angles and other draws of the envelope; constraints relative to the baseline hold against
// the baseline on the same sample). A design is recommended only if it meets the constraints on
// every replication; among those, the lowest mean objective wins. The in-sample
// optimum is biased low (the optimiser chose it on that sample): this is the honest comparison.
#include <cmath>
#include <limits>
#include <sstream>

#include "abuopt/common/text.hpp"
#include "study_context.hpp"

namespace abuopt::studies::detail {

void run_replicate_stage(StudyContext& c, const StageSpec& stage) {
  for (const ChoiceContext& ch : c.choices) {
    if (!ch.last_design) continue;
    StudyDesign& d = c.result.designs[*ch.last_design];
    d.replications.clear();
    double sum = 0;
    bool all = true;
    for (std::uint64_t seed : stage.seeds) {
      if (c.stop()) return;
      const opt::Evaluation e = c.evaluate_profile(c.fresh(ch.index, seed, stage.runs).settings, d.profile);
      d.replications.push_back(e);
      sum += e.objective;
      all = all && feasible(e);
    }
    d.robust_feasible = all;
    d.replicated_objective = sum / static_cast<double>(d.replications.size());
    std::ostringstream os;
    os << "stage " << stage.name << " (" << ch.label << "): " << d.label << " on " << stage.seeds.size()
       << " fresh samples: mean objective " << format_number(std::round(d.replicated_objective * 1000) / 1000)
       << (all ? ", feasible on every one" : ", NOT feasible on every one");
    c.log(os.str());
  }
  for (const ChoiceContext& ch : c.choices) {
    if (!ch.last_design) continue;
    const StudyDesign& d = c.result.designs[*ch.last_design];
    if (!d.robust_feasible) continue;
    if (!c.result.recommended || d.replicated_objective < c.result.designs[*c.result.recommended].replicated_objective)
      c.result.recommended = *ch.last_design;
  }
  if (!c.result.recommended) {
    recommend_in_sample(c);
    c.result.candidate = c.result.recommended.has_value();
    c.result.notes.push_back(
        c.result.recommended
            ? "no design met the constraints on every fresh sample; the recommendation is the best in-sample design, "
              "which did not hold up: treat it as a candidate, not an answer"
            : "no design met the constraints, in sample or on fresh samples");
    c.log("note: " + c.result.notes.back());
  }
}

}  // namespace abuopt::studies::detail
