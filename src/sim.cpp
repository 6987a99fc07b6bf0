/// \file
/// \brief The one definition of the arm layer's heavy entry points (arm/, sim/) for the
/// targets that link softrne::sim_compiled (see SOFTRNE_SIM_INLINE in softrne/config.hpp).
#define SOFTRNE_COMPILING_SIM
#include "softrne/arm/arm_description.hpp"
#include "softrne/arm/arm_dynamics.hpp"
#include "softrne/arm/equilibrium.hpp"
#include "softrne/arm/markers.hpp"
#include "softrne/sim/arm_simulation.hpp"
#include "softrne/sim/arm_jacobian.hpp"
#include "softrne/sim/closed_loop.hpp"
#include "softrne/sim/linearisation.hpp"
