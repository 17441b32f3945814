// Splitting sweeps over processes with MPI. Launched by mpirun, every rank computes its share
// of the cells and the results are combined exactly (each slot is filled by one rank and
// zero elsewhere, and x + 0 == x), so the table is byte-identical to a single-process run.
// Without mpirun, or in a build without MPI, this is a one-process no-op.
#pragma once
#include <atomic>
#include <vector>

#include "rosin/lab/Guettler.h"

namespace rosin::lab {

class Distributed {
public:
    static const Distributed& instance();
    int rank() const { return rank_; }
    int size() const { return size_; }
    bool isRoot() const { return rank_ == 0; }
    bool active() const { return active_; }
    /// Gathers every rank's results (and sample counts) into every rank.
    void combine(std::vector<CellResult>& results, std::atomic<long long>& samples) const;
    /// Waits until every rank has reached this point (a no-op in one process).
    void barrier() const;
    ~Distributed();

private:
    Distributed();
    int rank_ = 0, size_ = 1;
    bool active_ = false;
};

} // namespace rosin::lab
