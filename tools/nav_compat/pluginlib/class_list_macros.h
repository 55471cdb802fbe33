// The header slam_gmapping's nodelet includes (melodic's pluginlib name). Debian 12's pluginlib ships only the
// .hpp it has long forwarded to; this forwards to it. Build-environment shim of `make nav`, not upstream code.
#pragma once
#include <pluginlib/class_list_macros.hpp>
