#pragma once
// History-based self-repulsion of cloth (Selle ch. 6.4, eqs. 6.1-6.2, after Bridson, Fedkiw &
// Anderson 2002 sec. 7.2). At the start of each collision step (step A) the point-triangle and
// edge-edge pairs within reach are found and each remembers its side: a point the side of its
// triangle it is on (the triangle's normal is oriented towards it), an edge pair the direction s0
// of the shortest vector between them. Within the inner steps, a pair closer than the thickness h
// along that remembered normal n,
//   d = h - (x_p - sum w_i x_i) . n   (eq. 6.2; for edges the closest points' distance),
// gets an inelastic impulse that stops its approach (I_c = m v_N / 2 for equal masses) and, on
// the velocity that moves the positions only (step B.2), the elastic one of eq. 6.1,
//   I_r = -min(dt k d, m (0.1 d / dt - v_N)),
// a spring of stiffness k capped so that it never pushes the pair apart by more than a tenth of
// the overlap per step (which needs no damping). A pair that has crossed keeps its remembered
// normal, so d grows past h and the repulsion pulls it back instead of pushing it through. The
// end-of-step velocity (step B.8) gets the inelastic impulse and Coulomb friction scaled by it,
// not the elastic one (elastic impulses there cause artefacts, ch. 6.4). Pairs are processed
// Gauss-Seidel, points before edges (they are more robust, ch. 6.4). m is the pair's effective
// mass (contact_stencil.hpp), which is the seed's m for equal masses.
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/solids/collision_pairs.hpp"
#include "msim/solids/contact_stencil.hpp"
#include "msim/solids/particle_split.hpp"

namespace msim::solids {

struct RepulsionSettings {
  double thickness = 0.01;  // h [m] (Table 6.1: 0.01)
  double stiffness = 1.0;   // k of eq. 6.1 [N/m]
  double friction = 0.3;    // mu of cloth on cloth
  // An edge pair's remembered side flips when s0 . s < epsilon |s| (ch. 6.4: 0 is aggressive,
  // 0.9 conservative; the test penalises rigid rotation of the pair).
  double edgeFlipEpsilon = 0.0;
};

struct RepulsionStats {
  int pointTrianglePairs = 0, edgeEdgePairs = 0;  // found in step A
};

class SelfRepulsion {
 public:
  explicit SelfRepulsion(const RepulsionSettings& settings = {}) : settings_(settings) {}
  const RepulsionSettings& settings() const { return settings_; }

  // Step A: the pairs that come within h of each other while the particles move from x towards
  // `predicted` (their boxes span both, grown by h), with their sides at x.
  void findPairs(CollisionPairs& pairs, const std::vector<Vec3>& x, const std::vector<Vec3>& predicted);

  // Step B.2 on the position-update velocity v at positions x (inelastic, then elastic impulses),
  // or step B.8 on the end-of-step velocity (inelastic and friction). inverseMass: 1 / m per
  // particle, 0 for pinned ones. Returns the pairs that were closer than h.
  int repelPositionVelocity(const std::vector<Vec3>& x, std::vector<Vec3>& v, const std::vector<double>& inverseMass,
                            double dt);
  int repelEndVelocity(const std::vector<Vec3>& x, std::vector<Vec3>& v, const std::vector<double>& inverseMass);

  // Splits the work among processes (particle_split.hpp; null: this process alone): each finds the
  // pairs (step A) and examines the contacts of its own points and of the edges whose first vertex
  // it owns, and all join them, so that every process holds the contacts one process alone finds;
  // the Gauss-Seidel passes run in the split's two phases, whose order (the contacts that span
  // processes, in connected groups, before each process's own) replaces the pairs'.
  void setSplit(const ParticleSplit* split) { split_ = split; }

  RepulsionStats stats() const { return {static_cast<int>(pointTriangle_.size()), static_cast<int>(edgeEdge_.size())}; }

 private:
  enum class Pass { Inelastic, Elastic, EndOfStep };
  // A pair within reach at the current positions: the stencil of its relative position, the
  // remembered normal and the gap along it (negative once crossed).
  struct Contact {
    ContactStencil stencil;
    Vec3 normal;
    double gap = 0.0;
    int pair = 0;  // its pair: point-triangle pairs first, then edge-edge pairs
  };
  // The pairs closer than h at x (and crossed by less than 2 h), over a face or between the edges'
  // ends, in the pairs' order (points first); pairs whose particles have not moved since the last
  // call keep its finding.
  void gatherContacts(const std::vector<Vec3>& x);
  // With a split: every process's contacts on every process, in the pairs' order, and their particles
  // (the two-phase passes' items).
  void joinContacts();
  // Whether this process examines pair i (points' pairs first): with a split, the pairs of its own
  // points and of the edges whose first vertex it owns.
  bool examines(std::size_t pair) const;
  // One Gauss-Seidel pass over the gathered contacts; returns their count.
  int respond(Pass pass, std::vector<Vec3>& v, const std::vector<double>& inverseMass, double dt) const;
  // Contact c's impulse of the pass.
  void respond(Pass pass, const Contact& c, std::vector<Vec3>& v, const std::vector<double>& inverseMass, double dt) const;

  struct PointTriangleHistory {
    PointTrianglePair pair;
    bool flipped = false;  // the triangle's normal (b - a) x (c - a) points away from the point
  };
  struct EdgeEdgeHistory {
    EdgeEdgePair pair;
    Vec3 side = Vec3::Zero();  // s0: unit shortest vector from the second edge to the first
  };

  RepulsionSettings settings_;
  const CollisionPairs* mesh_ = nullptr;
  std::vector<PointTriangleHistory> pointTriangle_;
  std::vector<EdgeEdgeHistory> edgeEdge_;
  std::vector<PointTrianglePair> foundPointTriangle_;
  std::vector<EdgeEdgePair> foundEdgeEdge_;
  std::vector<std::vector<Contact>> blockContacts_;  // per block of pairs, joined into contacts_
  // Per pass of positions, shared by the many pairs of each face and edge (each in one record, which
  // a pair reads at once): every triangle's unit normal (zero without area), centroid and squared
  // distance from it to its farthest corner, every edge's midpoint and half length.
  struct FaceFrame {
    Vec3 normal, centroid;
    double radius2 = 0.0;
  };
  struct EdgeSphere {
    Vec3 midpoint;
    double halfLength = 0.0;
  };
  std::vector<FaceFrame> faces_;
  std::vector<EdgeSphere> edgeSpheres_;
  std::vector<Contact> contacts_;
  // The positions of the last gathering over the current pairs (gatheredValid_), and which particles
  // have moved since (gatherContacts examines again only the pairs they take part in).
  std::vector<Vec3> gatheredAt_;
  std::vector<char> moved_;
  bool gatheredValid_ = false;
  const ParticleSplit* split_ = nullptr;
  std::vector<std::array<int, 4>> contactParticles_;  // with a split: each joined contact's particles
  std::vector<double> contactRows_;                           // with a split: joinContacts' exchange
};

}  // namespace msim::solids
