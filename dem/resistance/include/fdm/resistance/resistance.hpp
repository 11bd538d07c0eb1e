// Umbrella header of the fdmResistance library (see docs/resistance.md).
#ifndef FDM_RESISTANCE_RESISTANCE_HPP
#define FDM_RESISTANCE_RESISTANCE_HPP
#include "fdm/resistance/blocks.hpp"
#include "fdm/resistance/far_field_series.hpp"
#include "fdm/resistance/full_range_forms.hpp"
#include "fdm/resistance/near_field_constants.hpp"
#include "fdm/resistance/pair_functions.hpp"
#include "fdm/resistance/sphere_wall.hpp"
#include "fdm/resistance/subgrid.hpp"
#include "fdm/resistance/two_sphere.hpp"
#endif
