#include "abuopt/optimizer/optimizer_options.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/config_fields.hpp"
#include "abuopt/optimizer/algorithms.hpp"
#include "abuopt/optimizer/problem.hpp"

namespace abuopt::opt {

std::string to_string(FiniteDifference kind) {
  return kind == FiniteDifference::Central ? "central" : "forward";
}

FiniteDifference finite_difference_from_string(const std::string& text, const std::string& key) {
  if (text == "forward") return FiniteDifference::Forward;
  if (text == "central") return FiniteDifference::Central;
  throw ConfigError(key, text.empty() ? "\"\"" : text, "must be one of: forward, central");
}

namespace {
void require(bool ok, const std::string& key, double value, const std::string& rule) {
  if (!ok) throw ConfigError("optimizer." + key, format_number(value), rule);
}
}  // namespace

void OptimizerOptions::validate() const {
  const AlgorithmInfo& info = find_algorithm(algorithm, "optimizer.algorithm");
  if (!local_algorithm.empty()) {
    const AlgorithmInfo& local = find_algorithm(local_algorithm, "optimizer.local_algorithm");
    if (local.family != AlgorithmFamily::LocalDerivativeFree && local.family != AlgorithmFamily::LocalGradient)
      throw ConfigError("optimizer.local_algorithm", local_algorithm, "must be a local algorithm (not global or AUGLAG)");
    if (local.name == "IPOPT" || local.name == "SAO")
      throw ConfigError("optimizer.local_algorithm", local_algorithm,
                        local.name + " cannot be a local algorithm of NLopt");
  }
  if (info.name == "SAO") sao.validate("sao");
  // The history keeps every evaluation: a budget beyond 1e7 is a typo, not a study.
  require(max_evaluations > 0, "max_evaluations", static_cast<double>(max_evaluations), "must be > 0");
  require(max_evaluations <= 10'000'000, "max_evaluations", static_cast<double>(max_evaluations),
          "must be <= 10000000 (the history keeps every evaluation)");
  require(std::isfinite(max_time_s) && max_time_s >= 0, "max_time_s", max_time_s, "must be >= 0 (0: no limit)");
  require(max_iterations >= 0, "max_iterations", static_cast<double>(max_iterations), "must be >= 0 (0: default)");
  require(std::isfinite(xtol_rel) && xtol_rel >= 0, "xtol_rel", xtol_rel, "must be >= 0");
  require(std::isfinite(ftol_rel) && ftol_rel >= 0, "ftol_rel", ftol_rel, "must be >= 0");
  require(std::isfinite(ftol_abs) && ftol_abs >= 0, "ftol_abs", ftol_abs, "must be >= 0");
  if (target) require(!std::isnan(*target), "target", *target, "must be a number");
  require(std::isfinite(constraint_tolerance) && constraint_tolerance >= 0, "constraint_tolerance",
          constraint_tolerance, "must be >= 0");
  require(std::isfinite(fd_relative_step) && fd_relative_step >= 0 && fd_relative_step < 0.5, "fd_relative_step",
          fd_relative_step, "must be in [0, 0.5) (0: automatic)");
  require(population >= 0, "population", static_cast<double>(population), "must be >= 0 (0: default)");
  require(std::isfinite(initial_step) && initial_step >= 0 && initial_step <= 1, "initial_step", initial_step,
          "must be in [0, 1] (a fraction of each variable's range; 0: automatic)");
  require(print_level >= 0 && print_level <= 12, "print_level", print_level, "must be in [0, 12]");
}

void describe_fields(FieldArchive& a, OptimizerOptions& o) {
  static const EnumNames<FiniteDifference> differences = {{FiniteDifference::Forward, "forward"},
                                                          {FiniteDifference::Central, "central"}};
  a.field("algorithm", o.algorithm);
  FieldOptions local;
  local.enabled = a.reading() || !o.local_algorithm.empty();  // empty: the default (never written)
  a.field("local_algorithm", o.local_algorithm, local);
  a.field("max_evaluations", o.max_evaluations, Rule::positive_at_most(1e7));
  a.field("max_time_s", o.max_time_s, Rule::non_negative());
  a.field("max_iterations", o.max_iterations, Rule::non_negative());
  a.field("xtol_rel", o.xtol_rel, Rule::non_negative());
  a.field("ftol_rel", o.ftol_rel, Rule::non_negative());
  a.field("ftol_abs", o.ftol_abs, Rule::non_negative());
  a.field("target", o.target);
  a.field("constraint_tolerance", o.constraint_tolerance, Rule::non_negative());
  a.field("finite_difference", o.finite_difference, differences);
  a.field("fd_relative_step", o.fd_relative_step, Rule::in_range(0.0, 0.49));
  a.field("seed", o.seed, Rule::non_negative());
  a.field("population", o.population, Rule::non_negative());
  a.field("initial_step", o.initial_step, Rule::in_range(0.0, 1.0));
  a.field("print_level", o.print_level, Rule::in_range(0, 12));
  a.field("handle_sigint", o.handle_sigint);
  a.field("keep_history", o.keep_history);
  FieldOptions eval_threads = FieldOptions::not_identity();
  eval_threads.enabled = a.reading() || o.evaluation_threads != 0;  // 0 (the default) is never written
  a.field("evaluation_threads", o.evaluation_threads, Rule::in_range(0, 1024), eval_threads);
  // the sao section is written with algorithm SAO; reading it is read_optimizer_options' job (the
  // settings may come from two places)
  std::string upper = o.algorithm;
  std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char c) { return std::toupper(c); });
  if (!a.reading() && upper == "SAO") a.nested("sao", o.sao);
}

std::string to_yaml(const OptimizerOptions& o) { return write_fields(o); }

OptimizerOptions read_optimizer_options(YamlReader& r, YamlReader* sao_section) {
  OptimizerOptions o;
  {
    YamlReadArchive a(r);
    describe_fields(a, o);
  }
  if (!r.has("target")) r.get_double_or("target", 0.0);  // marks an explicit `target: null` as read
  find_algorithm(o.algorithm, r.key_path("algorithm"));
  if (!o.local_algorithm.empty()) find_algorithm(o.local_algorithm, r.key_path("local_algorithm"));
  const bool is_sao = find_algorithm(o.algorithm).name == "SAO";
  YamlReader nested = r.child("sao");
  const bool outer = sao_section && sao_section->present();
  if (nested.present() && outer)
    throw ConfigError(nested.path(), "<section>", "SAO settings are given twice (also as " + sao_section->path() +
                                                      "); keep one");
  YamlReader* sao = nested.present() ? &nested : outer ? sao_section : nullptr;
  if (sao) {
    if (!is_sao)
      throw ConfigError(sao->path(), "<section>",
                        "only used with " + r.key_path("algorithm") + ": SAO (algorithm is " + o.algorithm + ")");
    o.sao = read_sao_options(*sao);
  }
  r.finish();
  o.validate();
  return o;
}

}  // namespace abuopt::opt
