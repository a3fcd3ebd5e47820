#pragma once
// The processes of one run and what host code between kernels exchanges among them. `mpirun -np R kushner ...`
// gives each of R processes (ranks) one contiguous share of the members (engine/member_share.hpp); every
// number reported over members is then combined here, in an order that does not depend on R, so the output
// files are the same bytes for any R. A run without mpirun is one process, and every call below is the
// identity or a copy: that build and that run behave as before MPI existed.
//
// Declared here so that the reductions of kernels/ (ensemble moments, status counts, ASRE's pre-pass) can
// combine across processes; defined in engine/collectives.cpp, the one file that includes <mpi.h>. Every
// function but rank() and ranks() is collective: all processes call it, in the same order.
#include <string>
#include <vector>

namespace kushner::collective {

/// This process's index among ranks(), 0 .. ranks() - 1; 0 without MPI.
int rank();
/// Processes in the run; 1 without MPI.
int ranks();

long sum(long local);
long min(long local);
long max(long local);
bool any(bool local);

/// Every process's `local`, concatenated in rank order, on every process.
std::vector<double> gather(const std::vector<double>& local);

/// `value` as rank `root` holds it, on every process (strings of any length: a few rows of CSV).
std::string broadcast(const std::string& value, int root);
std::vector<double> broadcast(const std::vector<double>& value, int root);

}  // namespace kushner::collective
