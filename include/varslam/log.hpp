#pragma once
// Where varslam's log lines go (C++17). By default a library session writes warnings and errors to standard error
// and nothing to standard output. A caller routes them to its own logger (a ROS node to rosconsole, say) with
// set_log_sink, or silences them with LogLevel::Off.
#include <functional>
#include <string>

namespace varslam {

enum class LogLevel { Trace, Debug, Info, Warn, Error, Off };

/// Every line at `level` or above goes to `sink` (from any of varslam's threads, one line at a time). An empty sink
/// restores the default (standard error). Process-wide: call it before creating sessions.
void set_log_sink(std::function<void(LogLevel level, const std::string& line)> sink, LogLevel level = LogLevel::Info);
/// Changes only the level.
void set_log_level(LogLevel level);

}  // namespace varslam
