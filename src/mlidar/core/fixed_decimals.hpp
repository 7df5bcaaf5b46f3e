#pragma once
// Numbers in messages, terminal summaries and report pages.
#include <string>

namespace mlidar {

/// `value` with `digits` decimals ("%.*f"); "-" for NaN or infinity (a value not measured).
std::string fixed(double value, int digits);

}  // namespace mlidar
