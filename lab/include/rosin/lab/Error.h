// Errors the lab reports to people: one message naming the file and field at fault.
#pragma once
#include <optional>
#include <stdexcept>
#include <string>

namespace rosin::lab {

class LabError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// The number the whole of `text` spells, or nothing ("1e-3" is one; "0.5x", "" and "abc" are
/// not). NaN and infinities parse: whether they may stand is each caller's to say, in its words.
inline std::optional<double> wholeNumber(const std::string& text)
{
    try {
        std::size_t used = 0;
        const double v = std::stod(text, &used);
        if (used == text.size()) return v;
    } catch (const std::exception&) {
    }
    return std::nullopt;
}

} // namespace rosin::lab
