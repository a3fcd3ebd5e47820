#pragma once
// How the members of a run are split over MPI ranks: contiguous shares made of whole blocks of
// moment_block_size members (kernels/ensemble_moments.hpp), blocks dealt out as evenly as whole blocks allow,
// the extra ones to the last ranks. The ensemble moments reduce each block alone and merge the blocks in order, so when
// no block straddles two ranks the merged blocks, and every reported number, are the same bits for any number of ranks.
// Members draw their random numbers by global index (Seed::first_member), so a member's path is the same whichever rank
// runs it.
#include "kernels/rng.hpp"

#include <cstdint>

namespace kushner {

struct MemberShare {
  long first = 0;  // global index of this rank's first member
  long count = 0;  // members this rank runs (0 when there are fewer blocks than ranks)
  long total = 0;  // members of the whole run

  Seed seed(std::uint32_t value) const { return Seed(value, static_cast<std::uint32_t>(first)); }
  bool holds(long member) const { return member >= first && member < first + count; }
};

/// Rank `rank`'s share of `members` over `ranks` ranks.
MemberShare member_share(long members, int rank, int ranks);
/// This process's share (collective::rank() of collective::ranks()).
MemberShare member_share(long members);
/// The rank whose share holds global member `member`.
int member_owner(long member, long members);

}  // namespace kushner
