#pragma once
// weft verify's lines for a terminal (the front ends print them): the run's estimate before the
// work, and its verdict, figures and fits after it.
#include <string>

#include "weft/verify/plan.h"
#include "weft/verify/run.h"

namespace weft {

// "weft verify: quality Q, P M photons and N M particles: about T on C cores (...)\n".
std::string verify_estimate_text(const VerifyPlan& plan);
// The report's folder, incidences, quality and time; the verdict; each model's figures with
// their uncertainty; the metrics against the measurement; the fits.
std::string verify_summary_text(const VerifyPlan& plan, const VerifyReport& report, double seconds);

}  // namespace weft
