#pragma once
// The terms abuopt's reports use (I_r, I_r,x, %MI, %LC, "+-", units), defined once, so that
// `abuopt --help` and the report files (reproduce's report.md) say the same thing
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
// One line naming the terms and where they are defined (`abuopt --help`), for the commands that
// print them: the whole block is in `abuopt --help` and in report files, not after every command.
std::string terms_pointer();

}  // namespace abuopt
