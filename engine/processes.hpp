#pragma once
// The run's processes as the command line sees them: starting and ending MPI, ending every rank on an error,
// and the progress counts that rank 0's progress bar shows for all ranks. Defined with the collectives in
// engine/collectives.cpp; without MPI (a build without it, or a run without mpirun) there is one process.
#include <string>
#include <vector>

namespace kushner {

/// MPI_Init when the process was started by mpirun (or another launcher that sets OMPI_COMM_WORLD_SIZE,
/// PMIX_RANK or PMI_RANK); otherwise nothing, so a plain `kushner` run never touches MPI. MPI_Finalize at the end.
class ProcessGroup {
 public:
  ProcessGroup(int& argc, char**& argv);
  ~ProcessGroup();
  ProcessGroup(const ProcessGroup&) = delete;
  ProcessGroup& operator=(const ProcessGroup&) = delete;
};

/// Whether this build can split a run over MPI ranks.
bool mpi_compiled();

/// Ranks on this node and this rank's index among them (OMPI_COMM_WORLD_LOCAL_SIZE/_RANK); 1 and 0 without MPI.
int local_ranks();
int local_rank();

/// Ranks of this node that allocate from the same memory as this one on backend `name`: every local rank on
/// the host, the ranks that share this rank's GPU on a GPU (engine/backend.cpp).
int ranks_sharing_memory(const std::string& name);

/// Ends every rank of the run with exit code `code` (MPI_Abort), or this process alone without MPI.
[[noreturn]] void end_all_ranks(int code);

/// Progress of every rank (non-blocking). Ranks other than 0 send their step count now and then; rank 0 reads
/// the latest count of each. finish_progress is collective and leaves no message in flight.
void send_progress(long done);
std::vector<long> latest_progress(long own_done);
void finish_progress();

}  // namespace kushner
