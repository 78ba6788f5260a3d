#pragma once
// Reproducing the 2003 report's published studies (spec section 7; docs/validation.md): the study
// files (reproduction_table.hpp), verdict statistics (verdicts.hpp), the report writer
// (reproduction_report.hpp) and the runner (reproduction_runner.hpp). Include this for all of it.
#include "abuopt/studies/reproduction_report.hpp"
#include "abuopt/studies/reproduction_runner.hpp"
#include "abuopt/studies/reproduction_table.hpp"
#include "abuopt/studies/verdicts.hpp"
