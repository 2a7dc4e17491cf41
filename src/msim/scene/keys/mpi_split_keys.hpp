#pragma once
// The split of a grid phenomenon among the processes of `mpirun -np N msim run` (msim/parallel;
// docs/parallel.md) from the scene's mpi.* keys: the block lattice (mpi.blocks, or the one with
// the least interface) and the ghost layers (mpi.ghost_layers, or what the phenomenon's schemes
// read). What a phenomenon cannot run split is refused before the run, naming the key.
#include <memory>
#include <string>

#include "msim/core/domain_split.hpp"
#include "msim/numerics/pressure/pcg.hpp"
#include "msim/numerics/pressure/projection.hpp"

namespace msim::scene {

struct Scene;

// InputError: `what` (at scene key `key`) does not run split among MPI processes yet.
[[noreturn]] void refuseSplit(const Scene& scene, const std::string& key, const std::string& what);

// This process's block of the scene's 3D grid under mpirun (null on one process). `needed` ghost
// layers are what the phenomenon's schemes read, `reads` says which (for the error when
// mpi.ghost_layers asks fewer); the pressure solve takes the domain's sides and the solver
// settings. InputError naming mpi.blocks, mpi.ghost_layers or the process count when the grid
// cannot be split so.
std::unique_ptr<DomainSplit<3>> sceneDomainSplit(const Scene& scene, int needed, const std::string& reads,
                                                 const numerics::DomainSides<3>& sides,
                                                 const numerics::PcgSettings& pressureSolve);

}  // namespace msim::scene
