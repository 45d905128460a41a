#include "riner/slab_ranks.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>

#ifdef RINER_HAVE_MPI
// The C API alone: Open MPI's C++ bindings (deprecated) need a library riner does not link.
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace riner {

namespace {

// mpirun (Open MPI, MPICH/PMI, PMIx) announces the job in the environment of every rank.
bool started_by_mpirun() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"}) {
    if (std::getenv(name)) return true;
  }
  return false;
}

}  // namespace

int SlabRanks::launched_size() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
    if (const char* size = std::getenv(name)) return std::max(1, std::atoi(size));
  }
  return 1;
}

namespace {

}  // namespace

bool SlabRanks::built_with_mpi() {
#ifdef RINER_HAVE_MPI
  return true;
#else
  return false;
#endif
}

SlabRanks::SlabRanks() {
#ifdef RINER_HAVE_MPI
  if (!started_by_mpirun()) return;
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (!initialised) MPI_Init(nullptr, nullptr);
  mpi_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm local;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &local);
  MPI_Comm_rank(local, &local_rank_);
  MPI_Comm_size(local, &local_size_);
  MPI_Comm_free(&local);
#endif
}

SlabRanks::~SlabRanks() {
#ifdef RINER_HAVE_MPI
  if (mpi_) {
    int finalised = 0;
    MPI_Finalized(&finalised);
    if (!finalised) MPI_Finalize();
  }
#endif
}

std::string SlabRanks::share(const std::string& from_leader) const {
#ifdef RINER_HAVE_MPI
  if (mpi_) {
    unsigned long long length = from_leader.size();
    MPI_Bcast(&length, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
    std::string text = from_leader;
    text.resize(length);
    if (length) MPI_Bcast(text.data(), static_cast<int>(length), MPI_CHAR, 0, MPI_COMM_WORLD);
    return text;
  }
#endif
  return from_leader;
}

bool SlabRanks::all_ok(bool ok) const {
#ifdef RINER_HAVE_MPI
  if (mpi_) {
    int mine = ok ? 1 : 0, all = 0;
    MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return all == 1;
  }
#endif
  return ok;
}

void SlabRanks::abort(int code) const {
#ifdef RINER_HAVE_MPI
  if (mpi_) MPI_Abort(MPI_COMM_WORLD, code);
#endif
  std::exit(code);
}

std::string new_claim_token() {
  const auto now = std::chrono::system_clock::now().time_since_epoch();
  char token[64];
  std::snprintf(token, sizeof(token), "%llx-%d",
                static_cast<unsigned long long>(
                    std::chrono::duration_cast<std::chrono::microseconds>(now).count()),
                static_cast<int>(getpid()));
  return token;
}

SlabRun::Claim claim_by_file(const std::filesystem::path& out, const std::string& token) {
  return [out, token](const Slab& slab) {
    char name[64];
    std::snprintf(name, sizeof(name), "slab_%04zu.", slab.index);
    const std::filesystem::path path = out / "slabs" / (name + token + ".claim");
    const int fd = ::open(path.c_str(), O_CREAT | O_EXCL | O_WRONLY, 0644);
    if (fd < 0) return false;  // another rank has it (or the folder is gone: it fails later)
    ::close(fd);
    return true;
  };
}

}  // namespace riner
