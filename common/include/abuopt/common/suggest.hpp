#pragma once
// "Did you mean ...?" for a misspelt config key, subcommand or flag.
//
//   edit_distance("rtoll", "rtol") == 1
//   closest_match("duraton_s", {"duration_s", "frequency_hz"}) == "duration_s"
//
// The distance is the optimal-string-alignment distance: insertions, deletions, substitutions and
// swaps of two neighbouring characters each cost 1 (so "fricton" and "frcition" are both one step
// from "friction"). Letters are compared case-insensitively, '-' and '_' as equal.
// A candidate is suggested when its distance is at most max(1, min(3, length / 3)) of the longer
// of the two words (short words must be close; "mu" never suggests "xi"), the nearest wins, ties go
// to the earlier candidate. A candidate that starts with the word (a truncated key such as "dur"
// for "duration_s") is also suggested when it is the only such candidate.
#include <optional>
#include <string>
#include <vector>

namespace abuopt {

std::size_t edit_distance(const std::string& a, const std::string& b);
std::optional<std::string> closest_match(const std::string& word, const std::vector<std::string>& candidates);
// "; did you mean 'x'?" or "".
std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace abuopt
