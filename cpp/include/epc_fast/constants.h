#pragma once

namespace epc_fast {

constexpr double pi = 3.141592653589793238462643383279502884;
constexpr double half_pi = pi / 2;
constexpr double deg_to_rad = pi / 180;
constexpr double um_to_mm = 1e-3;
constexpr double um_to_m = 1e-6;
constexpr double nm_to_mm = 1e-6;

}  // namespace epc_fast
