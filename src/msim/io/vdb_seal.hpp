#pragma once
// A checksum that msim stores inside the .vdb files it writes, so a frame read back (msim render,
// --resume) is checked against what the run wrote before OpenVDB parses it. OpenVDB trusts the
// sizes stored in a file (string lengths, compressed block sizes, child counts), so a damaged
// file could otherwise make it allocate tens of gigabytes or loop over garbage.
//
// The seal is a file-level string metadata entry, kVdbSealKey, holding 16 hex digits: the XXH3
// 64-bit hash of the whole file with those 16 digits written as '0'. It is ordinary VDB metadata,
// so other tools read the file as usual and show the entry.
#include <filesystem>
#include <string>

namespace msim::io {

inline constexpr const char* kVdbSealKey = "msim_checksum";
// The value written before sealing: the hash is computed over the file with this in place.
inline const std::string kVdbSealPlaceholder(16, '0');

// Computes the checksum of a file written with the placeholder seal and stores it in place.
// std::runtime_error if the file cannot be read or written or carries no placeholder seal.
void sealVdbFile(const std::filesystem::path& file);

enum class VdbSeal { Verified, Absent };

// Checks the seal of a file's bytes: Verified when it matches, Absent when the file has none
// (written by another tool). InputError naming `file` when the seal does not match (the file
// changed after msim wrote it). `bytes` is left as it was.
VdbSeal checkVdbSeal(std::string& bytes, const std::filesystem::path& file);

}  // namespace msim::io
