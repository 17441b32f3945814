// rosin-host validate: a validation pass in the spirit of pluginval (which Debian does not
// package), run against a built VST3 or LV2 in CI. Each check prints one line and the pass
// fails if any does.
#pragma once
#include <filesystem>
#include <ostream>

namespace rosin::host {

struct ValidateOptions {
    int openCloseCycles = 10;
    double walkSeconds = 2.0;       ///< audio while a second thread random-walks every parameter
    std::filesystem::path hidReplay; ///< a hid-recorder capture played as a controller (empty: none)
    unsigned seed = 1;
};

/// Runs every check; returns the number that failed (0: the plugin passed).
int validate(const std::filesystem::path& plugin, const ValidateOptions& options, std::ostream& log);

} // namespace rosin::host
