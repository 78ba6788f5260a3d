#pragma once
// Shared text of the study's reports (Markdown, HTML, JSON): the answer in numbers, profile text.
#include <string>

#include "abuopt/studies/study.hpp"
#include "study_context.hpp"

namespace abuopt::studies::detail {

// "0 -> 25 Hz in 1 s, 25 -> 29.5 Hz in 10 s, ... (19 s)"
std::string profile_text(const StartupProfile& p);
// "12.3 [11.8, 12.9]" (3 significant digits)
std::string interval_text(const Interval& i);
// A number with 3 significant digits ("n/a" when not finite).
std::string sig3(double v);
// A metric of an evaluation (NaN when absent).
double metric(const opt::Evaluation& e, const std::string& key);
// The drive in words: "ideal motor" or "PI drive (1 Hz setpoints, ...)".
std::string drive_text(const MotorModel& m);
// One sentence: better than the baseline, worse, or no difference the samples can tell.
std::string verdict_text(const ValidationResult& v);
// Why the headline says what it says ("feasible on every fresh sample and better than ...").
std::string headline_reason(Verdict v);
// How the ball choices did, in one or two sentences (which count or set won).
std::string choices_sentence(const StudyFile& f, const StudyResult& r);
// The HTML report (study_report_html.cpp).
std::string study_html(const StudyFile& f, const StudyResult& r);

}  // namespace abuopt::studies::detail
