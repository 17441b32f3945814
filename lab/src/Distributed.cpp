#include "rosin/lab/Distributed.h"

#include <cstdlib>

#ifdef ROSIN_HAVE_MPI
// The C API only: the deprecated C++ bindings would need an extra library.
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace rosin::lab {

const Distributed& Distributed::instance()
{
    static Distributed d;
    return d;
}

Distributed::Distributed()
{
#ifdef ROSIN_HAVE_MPI
    // Only initialise MPI when a launcher started us: a plain run stays a plain program.
    const bool launched = std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE") || std::getenv("PMIX_RANK");
    if (!launched) return;
    int initialised = 0;
    MPI_Initialized(&initialised);
    if (!initialised) MPI_Init(nullptr, nullptr);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    active_ = size_ > 1;
#endif
}

Distributed::~Distributed()
{
#ifdef ROSIN_HAVE_MPI
    int initialised = 0, finalised = 0;
    MPI_Initialized(&initialised);
    MPI_Finalized(&finalised);
    if (initialised && !finalised) MPI_Finalize();
#endif
}

void Distributed::barrier() const
{
#ifdef ROSIN_HAVE_MPI
    if (active_) MPI_Barrier(MPI_COMM_WORLD);
#endif
}

void Distributed::combine(std::vector<CellResult>& results, std::atomic<long long>& samples) const
{
    if (!active_) return;
#ifdef ROSIN_HAVE_MPI
    constexpr int kFields = 10;
    const std::size_t n = results.size();
    std::vector<double> packed(n * kFields, 0.0);
    for (std::size_t t = static_cast<std::size_t>(rank_); t < n; t += static_cast<std::size_t>(size_)) {
        const CellResult& c = results[t];
        double* p = &packed[t * kFields];
        p[0] = c.acceleration; p[1] = c.force; p[2] = c.beta; p[3] = c.firstSlipTime; p[4] = c.forceBeforeSlip;
        p[5] = c.firstJump; p[6] = c.transientPeriods; p[7] = static_cast<double>(c.regime);
        p[8] = c.peakTemperature; p[9] = c.variant;
    }
    MPI_Allreduce(MPI_IN_PLACE, packed.data(), static_cast<int>(packed.size()), MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    for (std::size_t t = 0; t < n; ++t) {
        const double* p = &packed[t * kFields];
        CellResult& c = results[t];
        c.acceleration = p[0]; c.force = p[1]; c.beta = p[2]; c.firstSlipTime = p[3]; c.forceBeforeSlip = p[4];
        c.firstJump = p[5]; c.transientPeriods = static_cast<int>(p[6]); c.regime = static_cast<Regime>(static_cast<int>(p[7]));
        c.peakTemperature = p[8]; c.variant = static_cast<int>(p[9]);
    }
    long long local = samples.load(), total = 0;
    MPI_Allreduce(&local, &total, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
    samples = total;
#else
    (void)results;
    (void)samples;
#endif
}

} // namespace rosin::lab
