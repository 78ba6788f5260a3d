#include "abuopt/common/suggest.hpp"

#include <algorithm>
#include <cctype>
#include <vector>

namespace abuopt {

namespace {

char fold(char c) {
  if (c == '-') return '_';
  return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
}

}  // namespace

std::size_t edit_distance(const std::string& a, const std::string& b) {
  const std::size_t n = a.size(), m = b.size();
  // d[i][j]: distance of a[0..i) and b[0..j); three rows suffice for the swap step.
  std::vector<std::size_t> prev2(m + 1), prev(m + 1), cur(m + 1);
  for (std::size_t j = 0; j <= m; ++j) prev[j] = j;
  for (std::size_t i = 1; i <= n; ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= m; ++j) {
      const bool same = fold(a[i - 1]) == fold(b[j - 1]);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (same ? 0 : 1)});
      if (i > 1 && j > 1 && fold(a[i - 1]) == fold(b[j - 2]) && fold(a[i - 2]) == fold(b[j - 1]))
        cur[j] = std::min(cur[j], prev2[j - 2] + 1);
    }
    prev2.swap(prev);
    prev.swap(cur);
  }
  return prev[m];
}

std::optional<std::string> closest_match(const std::string& word, const std::vector<std::string>& candidates) {
  if (word.empty()) return std::nullopt;
  std::optional<std::string> best;
  std::size_t best_d = 0;
  for (const std::string& c : candidates) {
    if (c.empty() || c == word) continue;
    const std::size_t longer = std::max(word.size(), c.size());
    const std::size_t limit = std::max<std::size_t>(1, std::min<std::size_t>(3, longer / 3));
    const std::size_t d = edit_distance(word, c);
    if (d <= limit && (!best || d < best_d)) {
      best = c;
      best_d = d;
    }
  }
  if (best) return best;
  // A truncated word: the one candidate it begins (at least 3 characters).
  if (word.size() >= 3) {
    std::optional<std::string> only;
    for (const std::string& c : candidates) {
      if (c.size() <= word.size()) continue;
      bool prefix = true;
      for (std::size_t k = 0; k < word.size() && prefix; ++k) prefix = fold(word[k]) == fold(c[k]);
      if (!prefix) continue;
      if (only && *only != c) return std::nullopt;
      only = c;
    }
    return only;
  }
  return std::nullopt;
}

std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates) {
  const auto m = closest_match(word, candidates);
  return m ? "; did you mean '" + *m + "'?" : std::string();
}

}  // namespace abuopt
