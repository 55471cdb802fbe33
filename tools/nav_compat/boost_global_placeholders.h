// Force-included by `make nav` (tools/nav.sh) into every source of the navigation stack and gmapping: Boost 1.81
// (Debian 12) keeps bind's placeholders (_1, _2, ...) out of the global namespace, which slam_gmapping (melodic)
// uses unqualified; Boost's own switch for the old behaviour is BOOST_BIND_GLOBAL_PLACEHOLDERS with boost/bind.hpp.
#pragma once
#define BOOST_BIND_GLOBAL_PLACEHOLDERS
#include <boost/bind.hpp>
