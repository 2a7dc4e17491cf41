#include "msim/io/obj.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/io/atomic_file.hpp"

namespace msim::io {

namespace {

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

}  // namespace

TriangleMesh readObj(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open OBJ file");
  TriangleMesh mesh;
  std::string line;
  int lineNo = 0;
  std::vector<int> corners;
  while (std::getline(in, line)) {
    ++lineNo;
    const auto fail = [&](const std::string& what) {
      throw InputError(path.string() + ":" + std::to_string(lineNo) + ": " + what);
    };
    std::string_view content(line);
    if (const auto hash = content.find('#'); hash != std::string_view::npos) content = content.substr(0, hash);
    const auto w = words(content);
    if (w.empty()) continue;

    if (w[0] == "v") {
      // An optional fourth (homogeneous weight) or colour components may follow; only xyz matter.
      if (w.size() < 4) fail("expected 'v x y z'");
      Vec3 p;
      for (int a = 0; a < 3; ++a) {
        const char* last = w[a + 1].data() + w[a + 1].size();
        const auto [end, ec] = std::from_chars(w[a + 1].data(), last, p[a]);
        if (ec != std::errc() || end != last || !std::isfinite(p[a]))
          fail("expected a finite number, got '" + std::string(w[a + 1]) + "'");
      }
      mesh.vertices.push_back(p);
    } else if (w[0] == "f") {
      corners.clear();
      for (std::size_t k = 1; k < w.size(); ++k) {
        // Only the position index (before the first '/') matters.
        const std::string_view token = w[k].substr(0, w[k].find('/'));
        long index = 0;
        const char* last = token.data() + token.size();
        const auto [end, ec] = std::from_chars(token.data(), last, index);
        if (ec != std::errc() || end != last || token.empty())
          fail("expected a vertex index, got '" + std::string(w[k]) + "'");
        const long count = static_cast<long>(mesh.vertices.size());
        const long resolved = index < 0 ? count + index : index - 1;
        if (index == 0 || resolved < 0 || resolved >= count)
          fail("vertex index " + std::to_string(index) + " out of range (" + std::to_string(count) +
               " vertices defined so far)");
        corners.push_back(static_cast<int>(resolved));
      }
      if (corners.size() < 3) fail("a face needs at least 3 vertices, got " + std::to_string(corners.size()));
      for (std::size_t k = 1; k + 1 < corners.size(); ++k)
        mesh.triangles.push_back({corners[0], corners[k], corners[k + 1]});
    }
  }
  if (in.bad()) throw InputError(path.string() + ": read error");
  return mesh;
}

void writeObj(const std::filesystem::path& path, const TriangleMesh& mesh) {
  const std::size_t n = mesh.vertices.size();
  std::string text = "# written by msim\n";
  text.reserve(text.size() + 40 * n + 24 * mesh.triangles.size());
  for (const auto& v : mesh.vertices) text += fmt::format("v {:.9g} {:.9g} {:.9g}\n", v[0], v[1], v[2]);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (int v : tri)
      if (v < 0 || static_cast<std::size_t>(v) >= n)
        throw std::invalid_argument(fmt::format("triangle {} has vertex index {} outside [0, {}) ({})", t, v, n,
                                                path.string()));
    text += fmt::format("f {} {} {}\n", tri[0] + 1, tri[1] + 1, tri[2] + 1);
  }
  writeFileAtomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out) throw std::runtime_error("error writing " + tmp.string());
  });
}

}  // namespace msim::io
