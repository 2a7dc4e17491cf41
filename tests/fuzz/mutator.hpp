#pragma once
// Deterministic mutations of input files for the fuzz tests: byte-level damage (flipped bits,
// overwritten, inserted, deleted or repeated bytes, truncation, size fields set to extreme
// integers) and, for text formats, token-level edits that keep the file mostly well formed so the
// mutation reaches the checks behind the parser (numbers swapped for extreme or degenerate values,
// strings for odd ones, lines deleted, repeated or swapped).
#include <cstdint>
#include <random>
#include <string>

namespace msim::fuzz {

class Mutator {
 public:
  explicit Mutator(std::uint64_t seed) : rng_(seed) {}

  // One to four byte-level mutations.
  std::string mutateBytes(std::string bytes);
  // One to three text-level mutations, or byte-level ones a fifth of the time.
  std::string mutateText(std::string text);

 private:
  std::size_t position(std::size_t size);  // uniform in [0, size)
  void mutateOneByteWise(std::string& bytes);
  void mutateOneTextWise(std::string& text);

  std::mt19937_64 rng_;
};

}  // namespace msim::fuzz
