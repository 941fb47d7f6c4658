// The time integrators of the pulse solver.
#pragma once

namespace hemotree {

// adams_bashforth2: the paper's explicit scheme, time step bounded by the friction stiffness
// of the smallest vessels; exponential_ab2: the same with the linear friction -r Q of each
// element integrated exactly (Cox & Matthews 2002 ETD2), so only the wave speed bounds the
// step; runge_kutta4: classical, explicit.
enum class TimeScheme { adams_bashforth2, exponential_ab2, runge_kutta4 };

}  // namespace hemotree
