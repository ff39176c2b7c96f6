// SPDX-License-Identifier: MIT
#pragma once

/// @file
/// The reference world's contact problem as the cone solver sees it (Eigen): for benchmarks,
/// solver comparisons and problem dumps. World users who only step and read states include
/// world.hpp, which exposes no Eigen type.

#include "rheofeed/ccp/problem.hpp"
#include "rheofeed/reference/world.hpp"

namespace rheofeed::reference {

/// The contact problem of `world`'s last step that had contacts (ccp/problem.hpp: per contact
/// (n, t1, t2) rows, N in 1/kg, r in m/s), as built before the solve: dense up to
/// Settings::dense_contact_limit contacts, matrix-free above. Empty before the first step with
/// contacts. The reference stays valid until the world's next step or destruction.
const ccp::Problem& lastContactProblem(const World& world);

}  // namespace rheofeed::reference
