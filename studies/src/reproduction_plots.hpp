#pragma once
// The reproduction's plots, one function per kind (private to studies/): each writes its data
// (CSV) and, through the Gnuplot helper, its script and PNG into `dir`.
#include <filesystem>

#include "abuopt/common/gnuplot.hpp"
#include "abuopt/studies/reproduction_report.hpp"

namespace abuopt::studies_detail {

PlotNote plot_trend(const Gnuplot& gp, const TableResult& t, const PlotRequest& req, const std::filesystem::path& dir);
PlotNote plot_final_positions(const Gnuplot& gp, const TableResult& t, const PlotRequest& req,
                              const std::filesystem::path& dir);
PlotNote plot_settling(const Gnuplot& gp, const TableResult& t, const PlotRequest& req, const std::filesystem::path& dir);
PlotNote plot_equilibrium(const Gnuplot& gp, const TableResult& t, const PlotRequest& req,
                          const std::filesystem::path& dir);

}  // namespace abuopt::studies_detail
