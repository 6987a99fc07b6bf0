#pragma once
/// \file
/// \brief Umbrella header of the core library (needs Eigen only).

#include "softrne/config.hpp"
#include "softrne/segments/constant_curvature_joint.hpp"
#include "softrne/segments/revolute_joint.hpp"
#include "softrne/segments/rigid_link.hpp"
#include "softrne/segments/segment_list.hpp"
#include "softrne/chain/static_chain.hpp"
#include "softrne/chain/dynamic_chain.hpp"
#include "softrne/algorithms/kinematics.hpp"
#include "softrne/algorithms/rnea.hpp"
#include "softrne/algorithms/bias.hpp"
#include "softrne/algorithms/mass_matrix.hpp"
#include "softrne/algorithms/forward_dynamics.hpp"
#include "softrne/algorithms/own_inertia.hpp"
#include "softrne/algorithms/articulated_body.hpp"
#include "softrne/algorithms/pressure_allocation.hpp"
#include "softrne/algorithms/derivatives.hpp"
