/// \file
/// \brief The one definition of the arm layer's heavy entry points (model/, sim/) for the
/// targets that link softrne::sim_compiled (see SOFTRNE_SIM_INLINE in softrne/config.hpp).
#define SOFTRNE_COMPILING_SIM
#include "softrne/model/arm_model.hpp"
#include "softrne/sim/arm_simulation.hpp"
