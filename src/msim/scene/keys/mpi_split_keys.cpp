#include "msim/scene/keys/mpi_split_keys.hpp"

#include <cmath>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/parallel/mpi_domain_split.hpp"
#include "msim/parallel/mpi_session.hpp"
#include "msim/scene/keys/json_vectors.hpp"
#include "msim/scene/scene_file.hpp"

namespace msim::scene {

void refuseSplit(const Scene& scene, const std::string& key, const std::string& what) {
  throw InputError(fmt::format("{}: '{}': {} does not run split among MPI processes yet; run the scene without mpirun",
                               scene.file.string(), key, what));
}

std::unique_ptr<DomainSplit<3>> sceneDomainSplit(const Scene& scene, int needed, const std::string& reads,
                                                 const numerics::DomainSides<3>& sides,
                                                 const numerics::PcgSettings& pressureSolve) {
  const int ranks = parallel::worldSize();
  if (ranks == 1) return nullptr;
  const std::string file = scene.file.string();
  const nlohmann::json& mpi = scene.resolved.at("mpi");
  const int asked = mpi.at("ghost_layers").get<int>();
  if (asked > 0 && asked < needed)
    throw InputError(fmt::format("{}: 'mpi.ghost_layers' is {} but {} reads {} layers of its neighbours; use {} or "
                                 "more, or 0",
                                 file, asked, reads, needed, needed));
  const int ghost = asked > 0 ? asked : needed;
  const GridSpec<3> global = scene.gridSpec<3>();
  const Vec<3> blocks = sceneVector<3>(mpi.at("blocks"));
  IVec<3> lattice;
  for (int a = 0; a < 3; ++a) {
    if (!(blocks[a] >= 0.0) || blocks[a] != std::floor(blocks[a]) || blocks[a] > ranks)
      throw InputError(fmt::format("{}: 'mpi.blocks' must hold whole numbers from 0 to {} (got {})", file, ranks,
                                   blocks[a]));
    lattice[a] = static_cast<int>(blocks[a]);
  }
  if (!lattice.isZero() && (lattice.array() == 0).any())
    throw InputError(fmt::format("{}: 'mpi.blocks' sets some axes but not all: give all three or none", file));
  const parallel::BlockDecomposition<3> decomposition =
      lattice.isZero() ? parallel::BlockDecomposition<3>(global.res, ranks, ghost,
                                                         file + ": mpirun -np " + std::to_string(ranks))
                       : parallel::BlockDecomposition<3>(global.res, lattice, ghost, file + ": 'mpi.blocks'");
  if (decomposition.ranks() != ranks)
    throw InputError(fmt::format("{}: 'mpi.blocks' makes {} blocks for {} processes (mpirun -np {})", file,
                                 decomposition.ranks(), ranks, ranks));
  const parallel::GridBlock<3> block(global, decomposition, parallel::worldRank(), ghost);
  return std::make_unique<parallel::MpiDomainSplit>(block, sides, pressureSolve, MPI_COMM_WORLD);
}

}  // namespace msim::scene
