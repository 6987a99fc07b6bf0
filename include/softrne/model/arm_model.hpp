#pragma once
/// \file
/// \brief Forwards to softrne/arm/arm_description.hpp and softrne/arm/arm_dynamics.hpp, where
/// the arm layer moved: model/ clashed with the Model/Data vocabulary of the chain (the chain
/// is the Model, its workspace the Data); kept so that code including it compiles. The names
/// (softrne::ArmDescription, build_arm, ArmDynamics, ...) did not change.

#include "softrne/arm/arm_description.hpp"
#include "softrne/arm/arm_dynamics.hpp"
