#include "msim/io/vdb_seal.hpp"

#include <xxhash.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>

#include "msim/core/error.hpp"

namespace msim::io {

namespace {

// How OpenVDB serialises a string metadata entry: the name and the type name as a little-endian
// 32-bit length and their characters, then the value's byte count and its bytes.
std::string sealRecordPrefix() {
  const auto lengthOf = [](std::size_t n) {
    const auto v = static_cast<std::uint32_t>(n);
    return std::string{char(v & 0xff), char((v >> 8) & 0xff), char((v >> 16) & 0xff), char(v >> 24)};
  };
  const std::string key = kVdbSealKey, type = "string";
  return lengthOf(key.size()) + key + lengthOf(type.size()) + type + lengthOf(kVdbSealPlaceholder.size());
}

// Offset of the seal's 16 digits in bytes, or npos.
std::size_t sealOffset(const std::string& bytes) {
  static const std::string prefix = sealRecordPrefix();
  const std::size_t at = bytes.find(prefix);
  if (at == std::string::npos || at + prefix.size() + kVdbSealPlaceholder.size() > bytes.size()) return std::string::npos;
  return at + prefix.size();
}

// The hash of bytes with the seal's digits (at offset) as the placeholder.
std::string sealOf(std::string& bytes, std::size_t offset) {
  const std::string stored = bytes.substr(offset, kVdbSealPlaceholder.size());
  std::copy(kVdbSealPlaceholder.begin(), kVdbSealPlaceholder.end(), bytes.begin() + static_cast<std::ptrdiff_t>(offset));
  const XXH64_hash_t hash = XXH3_64bits(bytes.data(), bytes.size());
  std::copy(stored.begin(), stored.end(), bytes.begin() + static_cast<std::ptrdiff_t>(offset));
  return fmt::format("{:016x}", hash);
}

}  // namespace

void sealVdbFile(const std::filesystem::path& file) {
  std::string bytes;
  {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read back " + file.string() + " to seal it");
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::size_t offset = sealOffset(bytes);
  if (offset == std::string::npos || bytes.compare(offset, kVdbSealPlaceholder.size(), kVdbSealPlaceholder) != 0)
    throw std::runtime_error(file.string() + ": no placeholder seal to fill");
  const std::string seal = sealOf(bytes, offset);
  std::fstream out(file, std::ios::binary | std::ios::in | std::ios::out);
  out.seekp(static_cast<std::streamoff>(offset));
  out.write(seal.data(), static_cast<std::streamsize>(seal.size()));
  out.close();
  if (!out) throw std::runtime_error("cannot write the seal of " + file.string());
}

VdbSeal checkVdbSeal(std::string& bytes, const std::filesystem::path& file) {
  const std::size_t offset = sealOffset(bytes);
  if (offset == std::string::npos) return VdbSeal::Absent;
  if (bytes.compare(offset, kVdbSealPlaceholder.size(), sealOf(bytes, offset)) != 0)
    throw InputError(fmt::format("{}: damaged VDB file: its content does not match the checksum msim stored when "
                                 "writing it ({} bytes now)",
                                 file.string(), bytes.size()));
  return VdbSeal::Verified;
}

}  // namespace msim::io
