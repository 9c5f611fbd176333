// Where the 10-20 (and common 10-10) electrodes sit on a flat head map, for scalp maps: the
// azimuthal projection from the vertex (Cz at the centre, the nose up, the right ear right), with
// the ring through Fpz, T7, Oz and T8 (90 degrees from Cz) at radius 0.5.
#pragma once

#include <optional>
#include <string>
#include <utility>

namespace arbci::bci {

// An electrode's name as the tables here and elsewhere key it (upper case): montages spell the
// same site "Pz", "PZ" or "pz".
std::string electrodeKey(const std::string& name);

// (x, y): x to the right ear, y to the nose; none for a name not in the table (case-insensitive;
// the old names T3, T4, T5, T6 are known too).
std::optional<std::pair<double, double>> electrodePosition(const std::string& name);

}  // namespace arbci::bci
