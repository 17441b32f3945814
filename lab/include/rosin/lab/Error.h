// Errors the lab reports to people: one message naming the file and field at fault.
#pragma once
#include <stdexcept>
#include <string>

namespace rosin::lab {

class LabError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

} // namespace rosin::lab
