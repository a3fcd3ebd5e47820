#pragma once
// How a long run reports progress without printing: the engine calls back with the number of steps done
// (over all its passes); the command line draws the bar (drivers/progress.hpp).
#include <functional>

namespace kushner {

using ProgressCallback = std::function<void(long steps_done)>;

}  // namespace kushner
