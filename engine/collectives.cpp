// The collectives of core/collectives.hpp, the process group of engine/processes.hpp and the member split of
// engine/member_share.hpp. The only file that includes <mpi.h> (KUSHNER_MPI is defined for it alone), so MPI
// adds one translation unit to the build, and nothing to the templates compiled per model.
#include "core/collectives.hpp"

#include "core/errors.hpp"
#include "engine/member_share.hpp"
#include "engine/processes.hpp"
#include "kernels/ensemble_moments.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>

#if defined(KUSHNER_MPI)
#include <mpi.h>
#endif

namespace kushner {

namespace {

#if defined(KUSHNER_MPI)
bool started = false;  // MPI_Init called by ProcessGroup
MPI_Comm world = MPI_COMM_NULL;
MPI_Comm progress_comm = MPI_COMM_NULL;  // its own communicator: progress messages never meet a collective's
constexpr int progress_tag = 1, final_tag = 2;
MPI_Request progress_request = MPI_REQUEST_NULL;
long progress_sent = 0;             // the buffer of the send in flight
std::vector<long> progress_latest;  // rank 0: the latest count of each rank

bool active() { return started && world != MPI_COMM_NULL; }

void check(int code, const char* what) {
  KUSHNER_REQUIRE(code == MPI_SUCCESS, what << " failed (MPI error " << code << ")");
}

long reduce(long local, MPI_Op op) {
  if (!active()) return local;
  long result = 0;
  check(MPI_Allreduce(&local, &result, 1, MPI_LONG, op, world), "MPI_Allreduce");
  return result;
}

bool launched_by_mpirun() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"})
    if (std::getenv(name) != nullptr) return true;
  return false;
}
#endif

int env_int(const char* name, int fallback) {
  const char* value = std::getenv(name);
  return value != nullptr && *value != '\0' ? std::atoi(value) : fallback;
}

}  // namespace

// ---- collectives ----------------------------------------------------------------------------------------------

namespace collective {

int rank() {
#if defined(KUSHNER_MPI)
  if (active()) {
    int r = 0;
    MPI_Comm_rank(world, &r);
    return r;
  }
#endif
  return 0;
}

int ranks() {
#if defined(KUSHNER_MPI)
  if (active()) {
    int r = 1;
    MPI_Comm_size(world, &r);
    return r;
  }
#endif
  return 1;
}

#if defined(KUSHNER_MPI)
long sum(long local) { return reduce(local, MPI_SUM); }
long min(long local) { return reduce(local, MPI_MIN); }
long max(long local) { return reduce(local, MPI_MAX); }
bool any(bool local) { return reduce(local ? 1 : 0, MPI_MAX) != 0; }

std::vector<double> gather(const std::vector<double>& local) {
  if (!active()) return local;
  const int n = ranks();
  const int count = static_cast<int>(local.size());
  std::vector<int> counts(n), offsets(n);
  check(MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, world), "MPI_Allgather");
  long total = 0;
  for (int r = 0; r < n; ++r) offsets[r] = static_cast<int>(total), total += counts[r];
  std::vector<double> all(total);
  check(MPI_Allgatherv(local.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, world),
        "MPI_Allgatherv");
  return all;
}

std::string broadcast(const std::string& value, int root) {
  if (!active()) return value;
  long size = static_cast<long>(value.size());
  check(MPI_Bcast(&size, 1, MPI_LONG, root, world), "MPI_Bcast");
  std::string out = rank() == root ? value : std::string(size, '\0');
  check(MPI_Bcast(out.data(), static_cast<int>(size), MPI_CHAR, root, world), "MPI_Bcast");
  return out;
}

std::vector<double> broadcast(const std::vector<double>& value, int root) {
  if (!active()) return value;
  long size = static_cast<long>(value.size());
  check(MPI_Bcast(&size, 1, MPI_LONG, root, world), "MPI_Bcast");
  std::vector<double> out = rank() == root ? value : std::vector<double>(size);
  check(MPI_Bcast(out.data(), static_cast<int>(size), MPI_DOUBLE, root, world), "MPI_Bcast");
  return out;
}
#else
long sum(long local) { return local; }
long min(long local) { return local; }
long max(long local) { return local; }
bool any(bool local) { return local; }
std::vector<double> gather(const std::vector<double>& local) { return local; }
std::string broadcast(const std::string& value, int) { return value; }
std::vector<double> broadcast(const std::vector<double>& value, int) { return value; }
#endif

}  // namespace collective

// ---- member shares -------------------------------------------------------------------------------------------

MemberShare member_share(long members, int rank, int ranks) {
  const long blocks = moment_blocks(members);
  // Blocks floor(r blocks / ranks) .. floor((r + 1) blocks / ranks) - 1 for rank r: shares differ by one block at
  // most, and the last rank, which holds the last (short) block, is one of those with the extra block, so no two
  // shares differ by more than 256 members.
  const long first_block = rank * blocks / ranks, end_block = (rank + 1L) * blocks / ranks;
  MemberShare share;
  share.total = members;
  share.first = std::min(members, first_block * moment_block_size);
  share.count = std::min(members, end_block * moment_block_size) - share.first;
  return share;
}

MemberShare member_share(long members) { return member_share(members, collective::rank(), collective::ranks()); }

int member_owner(long member, long members) {
  const int n = collective::ranks();
  for (int r = 0; r < n; ++r)
    if (member_share(members, r, n).holds(member)) return r;
  return 0;
}

// ---- the process group ---------------------------------------------------------------------------------------

ProcessGroup::ProcessGroup(int& argc, char**& argv) {
#if defined(KUSHNER_MPI)
  if (!launched_by_mpirun()) return;
  check(MPI_Init(&argc, &argv), "MPI_Init");
  started = true;
  world = MPI_COMM_WORLD;
  // Errors come back as codes and end up as one line through end_all_ranks, not MPI's own abort message.
  MPI_Comm_set_errhandler(world, MPI_ERRORS_RETURN);
  check(MPI_Comm_dup(world, &progress_comm), "MPI_Comm_dup");
#else
  (void)argc, (void)argv;
#endif
}

ProcessGroup::~ProcessGroup() {
#if defined(KUSHNER_MPI)
  if (!started) return;
  if (progress_comm != MPI_COMM_NULL) MPI_Comm_free(&progress_comm);
  world = MPI_COMM_NULL;
  MPI_Finalize();
#endif
}

bool mpi_compiled() {
#if defined(KUSHNER_MPI)
  return true;
#else
  return false;
#endif
}

int local_ranks() {
#if defined(KUSHNER_MPI)
  if (active()) return std::max(1, env_int("OMPI_COMM_WORLD_LOCAL_SIZE", 1));
#endif
  return 1;
}

int local_rank() {
#if defined(KUSHNER_MPI)
  if (active()) return std::max(0, env_int("OMPI_COMM_WORLD_LOCAL_RANK", 0));
#endif
  return 0;
}

void end_all_ranks(int code) {
#if defined(KUSHNER_MPI)
  if (active() && collective::ranks() > 1) MPI_Abort(world, code);
#endif
  std::exit(code);
}

// ---- progress of every rank ----------------------------------------------------------------------------------

#if defined(KUSHNER_MPI)
void send_progress(long done) {
  if (!active() || collective::rank() == 0) return;
  int finished = 1;
  if (progress_request != MPI_REQUEST_NULL) MPI_Test(&progress_request, &finished, MPI_STATUS_IGNORE);
  if (!finished) return;  // the previous count is still on its way: skip this one
  progress_sent = done;
  MPI_Isend(&progress_sent, 1, MPI_LONG, 0, progress_tag, progress_comm, &progress_request);
}

std::vector<long> latest_progress(long own_done) {
  const int n = collective::ranks();
  progress_latest.resize(n, 0);
  progress_latest[0] = own_done;
  if (!active()) return progress_latest;
  for (;;) {
    int waiting = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, progress_tag, progress_comm, &waiting, &status);
    if (!waiting) break;
    long done = 0;
    MPI_Recv(&done, 1, MPI_LONG, status.MPI_SOURCE, progress_tag, progress_comm, MPI_STATUS_IGNORE);
    progress_latest[status.MPI_SOURCE] = done;
  }
  return progress_latest;
}

void finish_progress() {
  if (!active() || collective::ranks() == 1) return;
  const int n = collective::ranks();
  if (collective::rank() != 0) {
    MPI_Wait(&progress_request, MPI_STATUS_IGNORE);
    long none = 0;
    check(MPI_Send(&none, 1, MPI_LONG, 0, final_tag, progress_comm), "MPI_Send");
    return;
  }
  // Messages from one rank arrive in the order sent: once its final message is here, none of its counts is left.
  for (int r = 1; r < n; ++r)
    for (;;) {
      long done = 0;
      MPI_Status status;
      check(MPI_Recv(&done, 1, MPI_LONG, r, MPI_ANY_TAG, progress_comm, &status), "MPI_Recv");
      if (status.MPI_TAG == final_tag) break;
    }
  progress_latest.clear();
}
#else
void send_progress(long) {}
std::vector<long> latest_progress(long own_done) { return {own_done}; }
void finish_progress() {}
#endif

}  // namespace kushner
