#pragma once
/// \file The readable tables `sph bench` prints as it goes (one line per result).

#include <string>
#include <vector>

#include <sph/bench/bench.h>

namespace sph::detail {

std::string neighbors_table_header();
std::string neighbors_table_row(const NeighborsRow& row);
std::string steps_table_header();
std::string steps_table_row(const StepsRow& row);
/// Time per particle-step against N, one line per (mode, precision, threads), one column per N.
std::string scaling_table(const std::vector<StepsRow>& rows);
std::string tank_table_header();
std::string tank_table_row(const TankRow& row);

}  // namespace sph::detail
