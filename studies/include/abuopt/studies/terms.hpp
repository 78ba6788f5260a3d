#pragma once
// The terms abuopt's reports use (I_r, I_r,x, %MI, %LC, "+-"), defined once, so that `--help`, the
// text summaries of montecarlo and optimize and reproduce's report.md say the same thing
// (definitions: /work/shared/spec/abu-model.md section 5, docs/validation.md).
#include <string>
#include <utility>
#include <vector>

namespace abuopt {

// {term, definition}, in the order they are printed.
const std::vector<std::pair<std::string, std::string>>& report_terms();
// "Terms:" and one wrapped entry per term, each line starting with `indent` (for terminals).
std::string terms_text(const std::string& indent = "  ", std::size_t width = 100);
// A Markdown list under "## Terms".
std::string terms_markdown();

}  // namespace abuopt
