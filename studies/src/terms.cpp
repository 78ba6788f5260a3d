#include "abuopt/studies/terms.hpp"

#include <sstream>

namespace abuopt {

const std::vector<std::pair<std::string, std::string>>& report_terms() {
  static const std::vector<std::pair<std::string, std::string>> t = {
      {"I_r", "residual imbalance: the imbalance left when the balls have stopped, in 1e-7 kg m. |I_r| is the "
              "magnitude of the whole imbalance vector m_I e (1, 0) + sum_i m_i l_i (cos beta_i, sin beta_i) (l_i: the ball track radius), "
              "which drives the vibration."},
      {"I_r,x", "the 2003 report's residual imbalance (its eq. 4.2), used in all its tables: the component along "
                "the imbalance, |m_I e + sum_i m_i l_i cos beta_i|; never larger than |I_r|."},
      {"%MI", "percentage of runs with more imbalance than without balls (I_r >= I = m_I e), for either "
              "definition; [lo, hi] or \"95 % CI\" is its 95 % Wilson score interval."},
      {"%LC", "percentage of runs whose balls are not all sticking at the end time (twice the profile's "
              "duration unless set): lasting motion, \"limit cycles\"."},
      {"+-", "after a mean, in every abuopt printout: the 95 % half-width of that mean, 1.96 standard errors "
             "(over the runs), so mean +- half-width is the 95 % interval (the error bars of every plot)."},
      {"units", "imbalances (I, I_r, I_r,x, their means and maxima) are printed in 1e-7 kg m in tables, summaries "
                "and plots; CSV and JSON files and the Python module give kg m (SI)."},
  };
  return t;
}

std::string terms_text(const std::string& indent, std::size_t width) {
  std::ostringstream os;
  os << indent << "Terms:\n";
  const std::size_t tab = 8;  // the definitions start in this column after the indent
  for (const auto& [term, text] : report_terms()) {
    std::string line = indent + "  " + term;
    line.resize(indent.size() + tab, ' ');
    std::istringstream words(text);
    std::string w;
    bool first = true;
    while (words >> w) {
      if (!first && line.size() + 1 + w.size() > width) {
        os << line << "\n";
        line = std::string(indent.size() + tab, ' ');
        first = true;
      }
      line += (first ? "" : " ") + w;
      first = false;
    }
    os << line << "\n";
  }
  return os.str();
}

std::string terms_pointer() {
  std::string names;
  for (const auto& [term, text] : report_terms()) names += (names.empty() ? "" : ", ") + term;
  return "Terms (" + names + "): abuopt --help";
}

std::string terms_markdown() {
  std::ostringstream os;
  os << "## Terms\n\n";
  for (const auto& [term, text] : report_terms()) os << "- **" << term << "**: " << text << "\n";
  os << "\n";
  return os.str();
}

}  // namespace abuopt
