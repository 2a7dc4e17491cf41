#include "mutator.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <string_view>
#include <vector>

namespace msim::fuzz {

namespace {

// Values that break size and count checks: zero, -1, sign and width limits.
constexpr std::array<std::int64_t, 10> kExtremeIntegers{0,          -1,         1,          0x7f,         0xff,
                                                        0x7fffffff, -0x80000000LL, 0xffffffffLL, 0x7fffffffffffffffLL,
                                                        0x100000000LL};

// Numbers a scene or mesh should reject or survive: degenerate, enormous, tiny, beyond double,
// integers past 32 bits, and tokens JSON does not accept.
constexpr std::array<std::string_view, 20> kExtremeNumbers{
    "0",    "-0",     "-1",   "1e308",  "-1e308",     "1e-308", "1e400",   "4294967296", "2147483648", "-2147483649",
    "1e9",  "0.5",    "3",    "1e-9",   "123456789012345678901234567890", "NaN", "inf", "-", "1e", "0x10"};

constexpr std::array<std::string_view, 10> kOddStrings{"\"\"",         "\"x\"",          "\"box\"",  "\"sphere\"",
                                                       "\"../../x\"",  "\"\\u0000\"",     "\"none\"", "\"closed\"",
                                                       "null",         "[]"};

bool isNumberStart(char c) { return (c >= '0' && c <= '9') || c == '-'; }
bool isNumberChar(char c) { return (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.' || c == 'e' || c == 'E'; }

}  // namespace

std::size_t Mutator::position(std::size_t size) {
  return size == 0 ? 0 : std::uniform_int_distribution<std::size_t>(0, size - 1)(rng_);
}

void Mutator::mutateOneByteWise(std::string& bytes) {
  const int kind = std::uniform_int_distribution<int>(0, 7)(rng_);
  if (bytes.empty()) {
    bytes.push_back(static_cast<char>(rng_()));
    return;
  }
  const std::size_t at = position(bytes.size());
  switch (kind) {
    case 0:  // flip one bit
      bytes[at] = static_cast<char>(bytes[at] ^ (1 << position(8)));
      break;
    case 1:  // any byte
      bytes[at] = static_cast<char>(rng_());
      break;
    case 2: {  // insert a few random bytes
      const std::size_t n = 1 + position(8);
      std::string extra(n, '\0');
      for (char& c : extra) c = static_cast<char>(rng_());
      bytes.insert(at, extra);
      break;
    }
    case 3:  // delete a run
      bytes.erase(at, 1 + position(16));
      break;
    case 4: {  // repeat a run
      const std::size_t n = std::min<std::size_t>(1 + position(64), bytes.size() - at);
      bytes.insert(at, bytes.substr(at, n));
      break;
    }
    case 5:  // truncate
      bytes.resize(at);
      break;
    case 6:
    case 7: {  // a 4- or 8-byte little-endian size field set to an extreme value
      const std::size_t width = kind == 6 ? 4 : 8;
      const std::int64_t v = kExtremeIntegers[position(kExtremeIntegers.size())];
      char raw[8];
      std::memcpy(raw, &v, sizeof raw);
      for (std::size_t k = 0; k < width && at + k < bytes.size(); ++k) bytes[at + k] = raw[k];
      break;
    }
  }
}

void Mutator::mutateOneTextWise(std::string& text) {
  const int kind = std::uniform_int_distribution<int>(0, 5)(rng_);
  if (kind <= 1) {  // a number token becomes an extreme one
    std::vector<std::size_t> starts;
    for (std::size_t i = 0; i < text.size(); ++i)
      if (isNumberStart(text[i]) && (i == 0 || !isNumberChar(text[i - 1]))) starts.push_back(i);
    if (starts.empty()) return mutateOneByteWise(text);
    const std::size_t begin = starts[position(starts.size())];
    std::size_t end = begin;
    while (end < text.size() && isNumberChar(text[end])) ++end;
    text.replace(begin, end - begin, kExtremeNumbers[position(kExtremeNumbers.size())]);
    return;
  }
  if (kind == 2) {  // a string token becomes an odd one
    std::vector<std::size_t> quotes;
    for (std::size_t i = 0; i < text.size(); ++i)
      if (text[i] == '"') quotes.push_back(i);
    if (quotes.size() < 2) return mutateOneByteWise(text);
    const std::size_t k = position(quotes.size() / 2) * 2;
    text.replace(quotes[k], quotes[k + 1] - quotes[k] + 1, kOddStrings[position(kOddStrings.size())]);
    return;
  }
  // Line edits: delete, repeat, or swap with another line.
  std::vector<std::size_t> lineStarts{0};
  for (std::size_t i = 0; i < text.size(); ++i)
    if (text[i] == '\n' && i + 1 < text.size()) lineStarts.push_back(i + 1);
  const auto lineAt = [&](std::size_t k) {
    const std::size_t begin = lineStarts[k];
    const std::size_t end = k + 1 < lineStarts.size() ? lineStarts[k + 1] : text.size();
    return std::pair{begin, end - begin};
  };
  const auto [begin, length] = lineAt(position(lineStarts.size()));
  const std::string line = text.substr(begin, length);
  if (kind == 3) {
    text.erase(begin, length);
  } else if (kind == 4) {
    text.insert(begin, line);
  } else {
    const auto [otherBegin, otherLength] = lineAt(position(lineStarts.size()));
    if (otherBegin == begin) return;
    const std::string other = text.substr(otherBegin, otherLength);
    // Replace the later line first so the earlier offset stays valid.
    if (otherBegin > begin) {
      text.replace(otherBegin, otherLength, line);
      text.replace(begin, length, other);
    } else {
      text.replace(begin, length, other);
      text.replace(otherBegin, otherLength, line);
    }
  }
}

std::string Mutator::mutateBytes(std::string bytes) {
  const int count = std::uniform_int_distribution<int>(1, 4)(rng_);
  for (int i = 0; i < count; ++i) mutateOneByteWise(bytes);
  return bytes;
}

std::string Mutator::mutateText(std::string text) {
  if (position(5) == 0) return mutateBytes(std::move(text));
  const int count = std::uniform_int_distribution<int>(1, 3)(rng_);
  for (int i = 0; i < count; ++i) mutateOneTextWise(text);
  return text;
}

}  // namespace msim::fuzz
