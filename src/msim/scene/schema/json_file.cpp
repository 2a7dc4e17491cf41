#include "msim/scene/schema/json_file.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>
#include <string>

#include "msim/core/error.hpp"

namespace msim::scene {
namespace {

struct TextPosition {
  std::size_t line;    // 1-based
  std::size_t column;  // 1-based
};

bool isWordChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '+' || c == '-'; }

// nlohmann reports the number of bytes read when the error was detected, i.e. the last character
// of the offending token (or the end of the file). People look for the start of a token, so step
// back over a complete string ("b") or a number/literal (tru, 1.5e).
std::size_t offendingTokenStart(const std::string& text, std::size_t bytesRead) {
  std::size_t at = std::min(bytesRead == 0 ? 0 : bytesRead - 1, text.size());
  if (at == text.size()) return at;
  if (text[at] == '"' && at > 0) {
    std::size_t open = at - 1;
    while (open > 0 && !(text[open] == '"' && text[open - 1] != '\\')) --open;
    return text[open] == '"' ? open : at;
  }
  while (at > 0 && isWordChar(text[at]) && isWordChar(text[at - 1])) --at;
  return at;
}

TextPosition positionOf(const std::string& text, std::size_t offending) {
  const auto begin = text.begin();
  const auto at = begin + static_cast<std::ptrdiff_t>(offending);
  const std::size_t line = 1 + static_cast<std::size_t>(std::count(begin, at, '\n'));
  const std::size_t lineStart = offending == 0 ? std::string::npos : text.rfind('\n', offending - 1);
  const std::size_t column = lineStart == std::string::npos ? offending + 1 : offending - lineStart;
  return {line, column};
}

// nlohmann's message is "[json.exception.parse_error.101] parse error at line L, column C: <what>";
// keep only <what> since we report the position ourselves.
std::string parseErrorReason(const std::string& message) {
  const std::size_t colon = message.find(": ");
  return colon == std::string::npos ? message : message.substr(colon + 2);
}

}  // namespace

nlohmann::json loadJsonFile(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError("scene file '" + path.string() + "' not found");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("scene file '" + path.string() + "' cannot be read");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  try {
    return nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const nlohmann::json::parse_error& e) {
    const TextPosition pos = positionOf(text, offendingTokenStart(text, e.byte));
    throw InputError(path.string() + ":" + std::to_string(pos.line) + ":" + std::to_string(pos.column) +
                     ": malformed JSON: " + parseErrorReason(e.what()));
  } catch (const nlohmann::json::out_of_range& e) {
    // A number beyond double's range ("1e400"); nlohmann names the token but not its place.
    const std::string message = e.what();
    const std::size_t open = message.find('\''), close = message.rfind('\'');
    const std::string token = open < close ? message.substr(open + 1, close - open - 1) : std::string();
    const std::size_t at = token.empty() ? std::string::npos : text.find(token);
    const std::string where =
        at == std::string::npos
            ? std::string()
            : ":" + std::to_string(positionOf(text, at).line) + ":" + std::to_string(positionOf(text, at).column);
    throw InputError(path.string() + where + ": the number " + (token.empty() ? "" : "'" + token + "' ") +
                     "is beyond the range of double");
  }
}

}  // namespace msim::scene
