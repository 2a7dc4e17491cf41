#pragma once
// Particles<D>: a structure of arrays. Positions and vector attributes are stored as Vecf<D>
// (float per coordinate, one contiguous array per channel), scalar attributes as float arrays.
// Single precision is enough for positions at the scales msim simulates (a 100 m domain still
// resolves 10 um), and halves the memory traffic of particle-heavy solvers.
//
// Attribute channels are created by name and every channel always holds size() entries, so a
// particle is the same index in every channel. Channels live in node-based maps: a reference
// returned by scalar()/vector() stays valid when other channels are added. Look a channel up
// once outside a loop; the lookup is by string.
#include <cstddef>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim {

template <int D>
class Particles {
 public:
  std::size_t size() const { return positions_.size(); }
  bool empty() const { return positions_.empty(); }

  std::vector<Vecf<D>>& positions() { return positions_; }
  const std::vector<Vecf<D>>& positions() const { return positions_; }

  // New channel filled with `initial` for the existing particles; later appended particles get
  // `initial` too. Adding a name that already exists is a programming error.
  std::vector<float>& addScalar(const std::string& name, float initial = 0.0f) {
    requireNewName(name);
    auto& channel = scalars_[name];
    channel.initial = initial;
    channel.values.assign(size(), initial);
    return channel.values;
  }
  std::vector<Vecf<D>>& addVector(const std::string& name, const Vecf<D>& initial = Vecf<D>::Zero()) {
    requireNewName(name);
    auto& channel = vectors_[name];
    channel.initial = initial;
    channel.values.assign(size(), initial);
    return channel.values;
  }

  bool hasScalar(const std::string& name) const { return scalars_.count(name) != 0; }
  bool hasVector(const std::string& name) const { return vectors_.count(name) != 0; }

  std::vector<float>& scalar(const std::string& name) { return find(scalars_, name, "scalar").values; }
  const std::vector<float>& scalar(const std::string& name) const { return find(scalars_, name, "scalar").values; }
  std::vector<Vecf<D>>& vector(const std::string& name) { return find(vectors_, name, "vector").values; }
  const std::vector<Vecf<D>>& vector(const std::string& name) const { return find(vectors_, name, "vector").values; }

  // Channel names in alphabetical order (deterministic output order for writers).
  std::vector<std::string> scalarNames() const { return names(scalars_); }
  std::vector<std::string> vectorNames() const { return names(vectors_); }

  // Grows or shrinks every channel; new particles get each channel's initial value and the origin.
  void resize(std::size_t n) {
    positions_.resize(n, Vecf<D>::Zero());
    for (auto& [name, c] : scalars_) c.values.resize(n, c.initial);
    for (auto& [name, c] : vectors_) c.values.resize(n, c.initial);
  }
  void reserve(std::size_t n) {
    positions_.reserve(n);
    for (auto& [name, c] : scalars_) c.values.reserve(n);
    for (auto& [name, c] : vectors_) c.values.reserve(n);
  }
  void clear() { resize(0); }

  // Appends one particle at `position`, every attribute at its channel's initial value; returns its
  // index so the caller can set attributes.
  std::size_t append(const Vecf<D>& position) {
    positions_.push_back(position);
    for (auto& [name, c] : scalars_) c.values.push_back(c.initial);
    for (auto& [name, c] : vectors_) c.values.push_back(c.initial);
    return positions_.size() - 1;
  }

  // Removes every particle i for which remove(i) is true, keeping the survivors in their order in
  // every channel. The predicate sees the particle set as it was before any removal, so it may
  // read any channel by index. Returns how many were removed.
  template <typename Predicate>
  std::size_t removeIf(Predicate&& remove) {
    const std::size_t n = size();
    keep_.resize(n);
    std::size_t kept = 0;
    for (std::size_t i = 0; i < n; ++i) {
      keep_[i] = remove(i) ? 0 : 1;
      kept += keep_[i];
    }
    if (kept == n) return 0;
    compact(positions_);
    for (auto& [name, c] : scalars_) compact(c.values);
    for (auto& [name, c] : vectors_) compact(c.values);
    return n - kept;
  }

 private:
  template <typename T>
  struct Channel {
    T initial{};
    std::vector<T> values;
  };

  void requireNewName(const std::string& name) const {
    if (hasScalar(name) || hasVector(name))
      throw std::invalid_argument("Particles: channel '" + name + "' already exists");
  }

  template <typename Map>
  static auto& find(Map& channels, const std::string& name, const char* kind) {
    auto it = channels.find(name);
    if (it == channels.end()) throw std::out_of_range(std::string("Particles: no ") + kind + " channel '" + name + "'");
    return it->second;
  }

  template <typename Map>
  static std::vector<std::string> names(const Map& channels) {
    std::vector<std::string> out;
    out.reserve(channels.size());
    for (const auto& entry : channels) out.push_back(entry.first);
    return out;
  }

  template <typename T>
  void compact(std::vector<T>& values) const {
    std::size_t out = 0;
    for (std::size_t i = 0; i < values.size(); ++i)
      if (keep_[i]) values[out++] = values[i];
    values.resize(out);
  }

  std::vector<Vecf<D>> positions_;
  std::map<std::string, Channel<float>> scalars_;
  std::map<std::string, Channel<Vecf<D>>> vectors_;
  std::vector<std::uint8_t> keep_;  // removeIf scratch, kept to avoid reallocating every call
};

}  // namespace msim
