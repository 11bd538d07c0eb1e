// Far-field series of the two-sphere resistance scalars for any size ratio lambda = a2/a1: the coefficients
// f_k(lambda) of the expansions in powers of t = 2/s' (s' = 2r/(a1+a2)), from the twin-multipole
// recurrences of Jeffrey & Onishi, J. Fluid Mech. 139 (1984) 261 (A, B, C; "J&O" (3.9)-(3.12), (4.6)-(4.11),
// (7.3)-(7.5)) and Jeffrey, Phys. Fluids A 4 (1992) 16 (G, H, M; "J92" (58), (73)-(76)), as corrected by
// Townsend, Phys. Fluids 35 (2023) 127126 ("T23"); the G, H, M series are read from the tables as in
// Ichiki et al. (2013) (equation numbers at each series in far_field_series.cpp).  The recurrences are
// lambda-independent: each is run once per process (truncated as in T23's generator) and reduced to a
// coefficient triangle, so that a new lambda costs an O(order^2) sum.  These sums give the near-field O(1)
// constants (near_field_constants.hpp) and the full-range forms (full_range_forms.hpp).
#ifndef FDM_RESISTANCE_FAR_FIELD_SERIES_HPP
#define FDM_RESISTANCE_FAR_FIELD_SERIES_HPP

#include "fdm/resistance/pair_functions.hpp"

namespace fdm {
namespace resistance {

// Far-field series coefficient f_k(lambda) of J&O (3.15)/(9), J92, as tabulated by T23's generator (test data
// two_sphere_general_lambda/farfield_fk.csv: "XA","YA","YB","YC","XG","YG","YH"); also XP,
// the pressure-moment series built here from the X^A table (X11P = sum_odd, X12P = -sum_even of
// f_k/(2(1+lambda))^k t^k, t = 2/s'; docs/resistance.md, "Pressure moment X^P"), and XQ, the same from
// the strain table of X^M (X11Q = sum_even, X12Q = +sum_odd; built with the M recurrences on first use).
double farFieldCoefficient(PairFunction family, int k, double lambda);

}  // namespace resistance
}  // namespace fdm

#endif
