// abuopt simulate CONFIG: one startup from given initial ball angles; prints the outcome.
#include <optional>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "abuopt/common/config_sections.hpp"
#include "abuopt/common/config_error.hpp"
#include "abuopt/common/number_text.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/core/monte_carlo.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "abuopt/core/simulator.hpp"
#include "commands/commands.hpp"

namespace abuopt::app {

namespace {

struct SimulateArgs {
  std::string config;
  std::string beta0;
  std::optional<double> mu;
  std::string trajectory;
  double trajectory_interval_s = 0.01;
  bool json = false;
};

std::vector<double> parse_angles(const std::string& text, std::size_t balls) {
  const std::vector<double> out =
      parse_number_list(text, ',', "--beta0", "must be a comma-separated list of finite angles in rad");
  if (out.size() != balls)
    throw ConfigError("--beta0", text, "must give " + std::to_string(balls) + " angles (one per ball)");
  return out;
}

int run_simulate(const SimulateArgs& a) {
  YamlReader root = YamlReader::load_file(a.config);
  SimulationSetup setup = read_simulation_setup(root);
  // A montecarlo section (a config that `abuopt montecarlo` also runs) is checked and not used.
  if (root.has("montecarlo") || root.has("envelope")) (void)read_monte_carlo_config(root, setup);
  finish_config(root);
  if (a.mu) {
    if (!(std::isfinite(*a.mu) && *a.mu >= 0 && *a.mu <= 0.999))
      throw ConfigError("--mu", format_number(*a.mu), "must be a friction coefficient in [0, 0.999]");
    setup.abu.friction_mu = *a.mu;
  }
  if (!(std::isfinite(a.trajectory_interval_s) && a.trajectory_interval_s > 0))
    throw ConfigError("--trajectory-interval", format_number(a.trajectory_interval_s), "must be a finite interval > 0 s");
  if (!a.trajectory.empty()) setup.options.trajectory_interval_s = a.trajectory_interval_s;
  const std::size_t n = setup.abu.balls.size();
  std::vector<double> beta0;
  if (!a.beta0.empty()) {
    beta0 = parse_angles(a.beta0, n);
  } else {
    for (std::size_t i = 0; i < n; ++i) beta0.push_back(2.0 * M_PI * (i + 0.5) / static_cast<double>(n) + 0.3);
  }
  Simulator sim(setup);
  if (!a.trajectory.empty()) {
    // The trajectory is kept in memory: cap what one request may ask for.
    constexpr double kMaxTrajectoryRows = 1e7;
    const double rows = sim.end_time_s() / a.trajectory_interval_s;
    if (rows > kMaxTrajectoryRows)
      throw ConfigError("--trajectory-interval", format_number(a.trajectory_interval_s),
                        "gives " + format_significant(rows, 3) + " samples over the " + format_number(sim.end_time_s()) +
                            " s run: at most 1e7 are allowed (about 1 GB); choose an interval >= " +
                            format_significant(sim.end_time_s() / kMaxTrajectoryRows, 3) + " s");
  }
  std::vector<TrajectoryPoint> traj;
  const RunOutcome o = sim.run(beta0, {}, a.trajectory.empty() ? nullptr : &traj);

  if (!a.trajectory.empty()) {
    AtomicFile f(a.trajectory);
    f << "t_s,frequency_hz,x_m,y_m";
    for (std::size_t i = 0; i < n; ++i) f << ",beta" << i + 1 << "_rad";
    for (std::size_t i = 0; i < n; ++i) f << ",mode" << i + 1;
    f << "\n";
    for (const auto& p : traj) {  // shortest round-trip numbers
      f << csv_number(p.t_s) << "," << csv_number(p.frequency_hz) << "," << csv_number(p.x_m) << "," << csv_number(p.y_m);
      for (double b : p.beta) f << "," << csv_number(b);
      for (int m : p.mode) f << "," << m;
      f << "\n";
    }
    f.commit();
  }

  const double I0 = setup.abu.imbalance_kgm();
  if (a.json) {
    nlohmann::json j;
    j["beta0"] = beta0;
    j["beta_final"] = o.beta_final;
    j["residual_imbalance"] = o.residual_imbalance_kgm;
    j["residual_imbalance_x"] = o.residual_imbalance_x_kgm;
    j["imbalance_without_balls"] = I0;
    j["settled"] = o.settled;
    j["settling_time"] = o.settling_time_s;
    j["max_amplitude_mm"] = o.max_amplitude_mm;
    j["status"] = to_string(o.status);
    j["message"] = o.message;
    j["rhs_evaluations"] = o.rhs_evaluations;
    j["steps"] = o.steps;
    j["events"] = o.events;
    j["end_time_s"] = o.end_time_s;
    j["wall_time_s"] = o.wall_time_s;
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << std::setprecision(6);
    std::cout << "status:               " << to_string(o.status) << (o.message.empty() ? "" : " (" + o.message + ")") << "\n";
    std::cout << "initial angles [rad]: ";
    for (double b : beta0) std::cout << b << " ";
    std::cout << "\nfinal angles [rad]:   ";
    for (double b : o.beta_final) std::cout << b << " ";
    // 1e-7 kg m as every other printout (the terms in `abuopt --help`); --json gives kg m (SI)
    std::cout << "\nresidual imbalance:   |I_r| = " << o.residual_imbalance_kgm * 1e7 << "e-7 kg m, I_r,x = "
              << o.residual_imbalance_x_kgm * 1e7 << "e-7 kg m (without balls: I = " << I0 * 1e7
              << "e-7 kg m, ratio |I_r| / I = " << o.residual_imbalance_kgm / I0 << ")\n";
    std::cout << "settled:              " << (o.settled ? "yes, at t = " + std::to_string(o.settling_time_s) + " s" : "no (balls still moving at the end: limit cycle)") << "\n";
    std::cout << "peak amplitude:       " << o.max_amplitude_mm << " mm\n";
    std::cout << "end time:             " << o.end_time_s << " s\n";
    std::cout << "cost:                 " << o.events << " stick/slip events, " << o.steps << " steps, "
              << o.rhs_evaluations << " RHS evaluations, " << o.wall_time_s * 1e3 << " ms\n";
    if (!a.trajectory.empty()) std::cout << "trajectory:           " << a.trajectory << " (" << traj.size() << " points)\n";
  }
  if (!o.ok()) {
    std::cerr << "abuopt: the simulation failed: " << to_string(o.status)
              << (o.message.empty() ? std::string() : ": " + o.message) << "\n";
    return 3;
  }
  return 0;
}

}  // namespace

void register_simulate(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* sub = app.add_subcommand("simulate",
                                     "Simulate one startup from given initial ball angles and print its outcome:\n"
                                     "final angles, residual imbalance (both definitions), settling, peak amplitude.\n"
                                     "Exit status: 0 ok, 2 bad input, 3 the simulation failed (status says why).");
  sub->add_option("config", args->config, "YAML config (sections abu, profile, motor, simulation)")->required();
  sub->add_option("--beta0", args->beta0, "initial ball angles in rad, comma-separated (default: evenly spread + 0.3)");
  // no CLI11 validators: their messages ("Value abc not in range ...", a 309-digit bound) are not
  // ours; run_simulate checks the converted values with the rules of their keys
  sub->add_option("--mu", args->mu, "override the friction coefficient abu.friction_mu (in [0, 0.999])");
  sub->add_option("--trajectory", args->trajectory, "write the trajectory (t, f, x, y, beta_i, modes) as CSV here");
  sub->add_option("--trajectory-interval", args->trajectory_interval_s, "trajectory sample interval in s (default 0.01)");
  sub->add_flag("--json", args->json, "print the outcome as one JSON object");
  sub->callback([args] { set_exit_code(run_simulate(*args)); });
}

}  // namespace abuopt::app
