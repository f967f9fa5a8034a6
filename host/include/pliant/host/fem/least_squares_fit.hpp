// Moved: the least-squares fit is no longer the FEM's alone (diagnosis uses it too). Include
// "pliant/host/least_squares_fit.hpp"; this header keeps code written against the old path
// building, and pliant::host::fem::fit_least_squares and its types still name the same things.
#pragma once

#include "pliant/host/least_squares_fit.hpp"
