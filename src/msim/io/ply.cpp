#include "msim/io/ply.hpp"

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <system_error>

#include "msim/core/error.hpp"
#include "msim/io/atomic_file.hpp"

namespace msim::io {

// Binary PLY data are read and written with memcpy of native values.
static_assert(std::endian::native == std::endian::little, "the PLY code assumes a little-endian host");

namespace {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

bool parseType(std::string_view name, PlyType& type) {
  struct Entry {
    std::string_view name;
    PlyType type;
  };
  static constexpr Entry kTypes[] = {
      {"char", PlyType::Int8},     {"int8", PlyType::Int8},       {"uchar", PlyType::UInt8},
      {"uint8", PlyType::UInt8},   {"short", PlyType::Int16},     {"int16", PlyType::Int16},
      {"ushort", PlyType::UInt16}, {"uint16", PlyType::UInt16},   {"int", PlyType::Int32},
      {"int32", PlyType::Int32},   {"uint", PlyType::UInt32},     {"uint32", PlyType::UInt32},
      {"float", PlyType::Float32}, {"float32", PlyType::Float32}, {"double", PlyType::Float64},
      {"float64", PlyType::Float64}};
  for (const auto& e : kTypes)
    if (e.name == name) {
      type = e.type;
      return true;
    }
  return false;
}

std::size_t typeSize(PlyType t) {
  switch (t) {
    case PlyType::Int8:
    case PlyType::UInt8: return 1;
    case PlyType::Int16:
    case PlyType::UInt16: return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32: return 4;
    case PlyType::Float64: return 8;
  }
  return 0;
}

bool isFloatType(PlyType t) { return t == PlyType::Float32 || t == PlyType::Float64; }

// Every PLY scalar type converts to double exactly, so one value representation serves them all.
struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32;
  bool isList = false;
  PlyType countType = PlyType::UInt8;
  std::vector<double> values;           // scalars: one per element; lists: all entries concatenated
  std::vector<std::size_t> listStarts;  // lists only: element i owns values[listStarts[i], listStarts[i+1])
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> properties;

  const PlyProperty* find(std::string_view propertyName) const {
    for (const auto& p : properties)
      if (p.name == propertyName) return &p;
    return nullptr;
  }
};

struct PlyFile {
  std::vector<PlyElement> elements;
  const PlyElement* find(std::string_view elementName) const {
    for (const auto& e : elements)
      if (e.name == elementName) return &e;
    return nullptr;
  }
};

class PlyParser {
 public:
  explicit PlyParser(const std::filesystem::path& path) : path_(path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path.string() + ": cannot open PLY file");
    bytes_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }

  PlyFile parse() {
    parseHeader();
    if (binary_)
      parseBinary();
    else
      parseAscii();
    return std::move(file_);
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw InputError(path_.string() + ": " + what); }
  [[noreturn]] void failAt(int line, const std::string& what) const {
    throw InputError(path_.string() + ":" + std::to_string(line) + ": " + what);
  }

  // Next line of the text part (header or ascii body) without its line break; false at the end.
  bool nextLine(std::string_view& line) {
    if (pos_ >= bytes_.size()) return false;
    const std::size_t end = bytes_.find('\n', pos_);
    const std::size_t stop = end == std::string::npos ? bytes_.size() : end;
    line = std::string_view(bytes_).substr(pos_, stop - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = end == std::string::npos ? bytes_.size() : end + 1;
    ++line_;
    return true;
  }

  static std::vector<std::string_view> words(std::string_view line) {
    std::vector<std::string_view> out;
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      const std::size_t start = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
      if (i > start) out.push_back(line.substr(start, i - start));
    }
    return out;
  }

  void parseHeader() {
    std::string_view line;
    if (!nextLine(line) || line != "ply") fail("not a PLY file (expected 'ply' on the first line)");
    bool haveFormat = false;
    while (true) {
      if (!nextLine(line)) fail("truncated PLY header (expected 'end_header')");
      const auto w = words(line);
      if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
      if (w[0] == "end_header") break;
      if (w[0] == "format") {
        if (w.size() != 3) failAt(line_, "expected 'format <encoding> 1.0'");
        if (w[1] == "ascii")
          binary_ = false;
        else if (w[1] == "binary_little_endian")
          binary_ = true;
        else if (w[1] == "binary_big_endian")
          failAt(line_, "binary_big_endian PLY is not supported (expected ascii or binary_little_endian)");
        else
          failAt(line_, "unknown PLY format '" + std::string(w[1]) + "'");
        haveFormat = true;
      } else if (w[0] == "element") {
        std::size_t count = 0;
        if (w.size() != 3 || !parseInteger(w[2], count)) failAt(line_, "expected 'element <name> <count>'");
        file_.elements.push_back(PlyElement{std::string(w[1]), count, {}});
      } else if (w[0] == "property") {
        if (file_.elements.empty()) failAt(line_, "property before any element");
        PlyProperty p;
        if (w.size() == 3 && parseType(w[1], p.type)) {
          p.name = w[2];
        } else if (w.size() == 5 && w[1] == "list" && parseType(w[2], p.countType) && parseType(w[3], p.type) &&
                   !isFloatType(p.countType)) {
          p.isList = true;
          p.name = w[4];
        } else {
          failAt(line_, "expected 'property <type> <name>' or 'property list <int type> <type> <name>'");
        }
        file_.elements.back().properties.push_back(std::move(p));
      } else {
        failAt(line_, "unexpected PLY header keyword '" + std::string(w[0]) + "'");
      }
    }
    if (!haveFormat) fail("PLY header has no 'format' line");
  }

  template <typename I>
  static bool parseInteger(std::string_view s, I& out) {
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && end == s.data() + s.size();
  }

  // Parses one ascii token as `type`; false if it is not a valid value of that type.
  static bool parseAsciiValue(std::string_view s, PlyType type, double& out) {
    const char* last = s.data() + s.size();
    if (type == PlyType::Float32) {
      // Parse floats as float: parsing as double first would round twice.
      float f = 0.0f;
      const auto [end, ec] = std::from_chars(s.data(), last, f);
      out = f;
      return ec == std::errc() && end == last;
    }
    if (type == PlyType::Float64) {
      const auto [end, ec] = std::from_chars(s.data(), last, out);
      return ec == std::errc() && end == last;
    }
    long long v = 0;
    if (!parseInteger(s, v)) return false;
    const std::size_t bits = typeSize(type) * 8;
    const bool isSigned = type == PlyType::Int8 || type == PlyType::Int16 || type == PlyType::Int32;
    const long long lo = isSigned ? -(1LL << (bits - 1)) : 0;
    const long long hi = isSigned ? (1LL << (bits - 1)) - 1 : (1LL << bits) - 1;
    out = static_cast<double>(v);
    return v >= lo && v <= hi;
  }

  double readBinaryValue(PlyType type, const PlyElement& e, std::size_t index) {
    const std::size_t n = typeSize(type);
    if (bytes_.size() - pos_ < n)
      fail("truncated PLY data: element '" + e.name + "' entry " + std::to_string(index) + " of " +
           std::to_string(e.count) + " is incomplete");
    const char* p = bytes_.data() + pos_;
    pos_ += n;
    switch (type) {
      case PlyType::Int8: return load<std::int8_t>(p);
      case PlyType::UInt8: return load<std::uint8_t>(p);
      case PlyType::Int16: return load<std::int16_t>(p);
      case PlyType::UInt16: return load<std::uint16_t>(p);
      case PlyType::Int32: return load<std::int32_t>(p);
      case PlyType::UInt32: return load<std::uint32_t>(p);
      case PlyType::Float32: return load<float>(p);
      case PlyType::Float64: return load<double>(p);
    }
    return 0.0;
  }

  template <typename T>
  static double load(const char* p) {
    T v;
    std::memcpy(&v, p, sizeof v);
    return static_cast<double>(v);
  }

  // Reserves storage only as far as the remaining bytes could hold, so a corrupt count in the
  // header produces a clean "truncated" error instead of a huge allocation.
  void reserveFor(PlyElement& e) {
    const std::size_t plausible = std::min(e.count, bytes_.size() - pos_);
    for (auto& p : e.properties) {
      if (p.isList)
        p.listStarts.reserve(plausible + 1);
      else
        p.values.reserve(plausible);
    }
  }

  void parseBinary() {
    for (auto& e : file_.elements) {
      // Entries without properties take no bytes: there is nothing to read however many there are.
      if (e.properties.empty()) continue;
      reserveFor(e);
      for (auto& p : e.properties)
        if (p.isList) p.listStarts.push_back(0);
      for (std::size_t i = 0; i < e.count; ++i) {
        for (auto& p : e.properties) {
          if (!p.isList) {
            p.values.push_back(readBinaryValue(p.type, e, i));
            continue;
          }
          const double length = readBinaryValue(p.countType, e, i);
          if (length < 0) fail("negative list length in element '" + e.name + "' " + std::to_string(i));
          for (std::size_t k = 0; k < static_cast<std::size_t>(length); ++k)
            p.values.push_back(readBinaryValue(p.type, e, i));
          p.listStarts.push_back(p.values.size());
        }
      }
    }
  }

  void parseAscii() {
    for (auto& e : file_.elements) {
      reserveFor(e);
      for (auto& p : e.properties)
        if (p.isList) p.listStarts.push_back(0);
      for (std::size_t i = 0; i < e.count; ++i) {
        std::string_view line;
        std::vector<std::string_view> w;
        while (w.empty()) {
          if (!nextLine(line))
            fail("truncated PLY data: element '" + e.name + "' has " + std::to_string(i) + " of " +
                 std::to_string(e.count) + " entries");
          w = words(line);
        }
        std::size_t t = 0;
        auto value = [&](PlyType type, const std::string& propertyName) {
          if (t >= w.size()) failAt(line_, "too few values for element '" + e.name + "' (at property '" + propertyName + "')");
          double v = 0.0;
          if (!parseAsciiValue(w[t], type, v))
            failAt(line_, "invalid value '" + std::string(w[t]) + "' for property '" + propertyName + "'");
          ++t;
          return v;
        };
        for (auto& p : e.properties) {
          if (!p.isList) {
            p.values.push_back(value(p.type, p.name));
            continue;
          }
          const double length = value(p.countType, p.name);
          if (length < 0) failAt(line_, "negative list length for property '" + p.name + "'");
          for (std::size_t k = 0; k < static_cast<std::size_t>(length); ++k) p.values.push_back(value(p.type, p.name));
          p.listStarts.push_back(p.values.size());
        }
        if (t != w.size())
          failAt(line_, "expected " + std::to_string(t) + " values for element '" + e.name + "', got " +
                            std::to_string(w.size()));
      }
    }
  }

  std::filesystem::path path_;
  std::string bytes_;
  std::size_t pos_ = 0;
  int line_ = 0;
  bool binary_ = false;
  PlyFile file_;
};

const PlyElement& requireElement(const PlyFile& file, const std::filesystem::path& path, std::string_view name) {
  const PlyElement* e = file.find(name);
  if (!e) throw InputError(path.string() + ": PLY file has no element '" + std::string(name) + "'");
  return *e;
}

const PlyProperty& requireScalar(const PlyElement& e, const std::filesystem::path& path, std::string_view name) {
  const PlyProperty* p = e.find(name);
  if (!p || p->isList)
    throw InputError(path.string() + ": PLY element '" + e.name + "' has no scalar property '" + std::string(name) + "'");
  return *p;
}

// Vertex i's coordinates; InputError for a NaN or infinite one (a damaged or foreign file), which
// would otherwise travel on into bounding boxes and voxelisation.
Vec3 vertexPosition(const PlyProperty* const (&xyz)[3], std::size_t i, const std::filesystem::path& path) {
  const Vec3 p(xyz[0]->values[i], xyz[1]->values[i], xyz[2]->values[i]);
  if (!p.allFinite()) throw InputError(path.string() + ": PLY vertex " + std::to_string(i) + " has a non-finite coordinate");
  return p;
}

std::vector<PointAttribute> vertexAttributesOf(const PlyElement& vertex) {
  std::vector<PointAttribute> attributes;
  for (const auto& p : vertex.properties) {
    if (p.isList || p.name == "x" || p.name == "y" || p.name == "z") continue;
    attributes.push_back(PointAttribute{p.name, std::vector<float>(p.values.begin(), p.values.end())});
  }
  return attributes;
}

// ---- writing ----

void checkAttributes(std::span<const PointAttribute> attributes, std::size_t count, const std::filesystem::path& path) {
  for (const auto& a : attributes) {
    const bool plainName = !a.name.empty() && a.name.find_first_of(" \t\r\n") == std::string::npos;
    if (!plainName || a.name == "x" || a.name == "y" || a.name == "z")
      throw std::invalid_argument("PLY attribute name '" + a.name + "' is not allowed (" + path.string() + ")");
    if (a.values.size() != count)
      throw std::invalid_argument("PLY attribute '" + a.name + "' has " + std::to_string(a.values.size()) +
                                  " values for " + std::to_string(count) + " vertices (" + path.string() + ")");
  }
}

// Appends values to the data section in the chosen encoding; ascii puts one element per line.
class PlyDataWriter {
 public:
  explicit PlyDataWriter(PlyEncoding encoding) : ascii_(encoding == PlyEncoding::Ascii) {}

  template <typename T>
  void put(T v) {
    if (!ascii_) {
      char raw[sizeof v];
      std::memcpy(raw, &v, sizeof v);
      data_.append(raw, sizeof v);
      return;
    }
    if (!atLineStart_) data_ += ' ';
    char text[64];
    // Shortest representation that parses back to the same value of type T.
    const auto r = std::to_chars(text, text + sizeof text, v);
    data_.append(text, r.ptr);
    atLineStart_ = false;
  }
  void endElement() {
    if (ascii_) data_ += '\n';
    atLineStart_ = true;
  }
  const std::string& data() const { return data_; }

 private:
  bool ascii_;
  bool atLineStart_ = true;
  std::string data_;
};

void writeBytes(const std::filesystem::path& target, const std::string& header, const std::string& data) {
  writeFileAtomically(target, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(header.data(), static_cast<std::streamsize>(header.size()));
    out.write(data.data(), static_cast<std::streamsize>(data.size()));
    out.close();
    if (!out) throw std::runtime_error("error writing " + tmp.string());
  });
}

std::string headerStart(PlyEncoding encoding) {
  return std::string("ply\nformat ") + (encoding == PlyEncoding::Ascii ? "ascii" : "binary_little_endian") +
         " 1.0\ncomment written by msim\n";
}

}  // namespace

void writePlyPoints(const std::filesystem::path& path, const PointCloud& points, PlyEncoding encoding) {
  const std::size_t n = points.positions.size();
  checkAttributes(points.attributes, n, path);
  std::string header = headerStart(encoding);
  header += "element vertex " + std::to_string(n) + "\nproperty float x\nproperty float y\nproperty float z\n";
  for (const auto& a : points.attributes) header += "property float " + a.name + "\n";
  header += "end_header\n";

  PlyDataWriter data(encoding);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) data.put(points.positions[i][a]);
    for (const auto& attr : points.attributes) data.put(attr.values[i]);
    data.endElement();
  }
  writeBytes(path, header, data.data());
}

PointCloud readPlyPoints(const std::filesystem::path& path) {
  const PlyFile file = PlyParser(path).parse();
  const PlyElement& vertex = requireElement(file, path, "vertex");
  const PlyProperty* xyz[3] = {&requireScalar(vertex, path, "x"), &requireScalar(vertex, path, "y"),
                               &requireScalar(vertex, path, "z")};
  PointCloud cloud;
  cloud.positions.resize(vertex.count);
  for (std::size_t i = 0; i < vertex.count; ++i) {
    const Vec3 p = vertexPosition(xyz, i, path);
    if (p.cwiseAbs().maxCoeff() > std::numeric_limits<float>::max())
      throw InputError(path.string() + ": PLY vertex " + std::to_string(i) + " lies beyond the range of float");
    cloud.positions[i] = p.cast<float>();
  }
  cloud.attributes = vertexAttributesOf(vertex);
  return cloud;
}

void writePlyMesh(const std::filesystem::path& path, const TriangleMesh& mesh,
                  std::span<const PointAttribute> vertexAttributes, const PlyWriteOptions& options) {
  const std::size_t n = mesh.vertices.size();
  checkAttributes(vertexAttributes, n, path);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int v : mesh.triangles[t])
      if (v < 0 || static_cast<std::size_t>(v) >= n)
        throw std::invalid_argument("triangle " + std::to_string(t) + " has vertex index " + std::to_string(v) +
                                    " outside [0, " + std::to_string(n) + ") (" + path.string() + ")");
  const bool asDouble = options.positionType == PlyPositionType::Float64;
  const std::string positionType = asDouble ? "double" : "float";
  std::string header = headerStart(options.encoding);
  header += "element vertex " + std::to_string(n) + "\n";
  for (const char* axis : {"x", "y", "z"}) header += "property " + positionType + " " + axis + "\n";
  for (const auto& a : vertexAttributes) header += "property float " + a.name + "\n";
  header += "element face " + std::to_string(mesh.triangles.size()) + "\nproperty list uchar int vertex_indices\n";
  header += "end_header\n";

  PlyDataWriter data(options.encoding);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      if (asDouble)
        data.put(mesh.vertices[i][a]);
      else
        data.put(static_cast<float>(mesh.vertices[i][a]));
    }
    for (const auto& attr : vertexAttributes) data.put(attr.values[i]);
    data.endElement();
  }
  for (const auto& tri : mesh.triangles) {
    data.put(std::uint8_t{3});
    for (int v : tri) data.put(static_cast<std::int32_t>(v));
    data.endElement();
  }
  writeBytes(path, header, data.data());
}

PlyMesh readPlyMesh(const std::filesystem::path& path) {
  const PlyFile file = PlyParser(path).parse();
  const PlyElement& vertex = requireElement(file, path, "vertex");
  const PlyElement& face = requireElement(file, path, "face");
  const PlyProperty* xyz[3] = {&requireScalar(vertex, path, "x"), &requireScalar(vertex, path, "y"),
                               &requireScalar(vertex, path, "z")};
  const PlyProperty* indices = face.find("vertex_indices");
  if (!indices) indices = face.find("vertex_index");
  if (!indices || !indices->isList)
    throw InputError(path.string() + ": PLY element 'face' has no list property 'vertex_indices'");

  PlyMesh out;
  out.mesh.vertices.resize(vertex.count);
  for (std::size_t i = 0; i < vertex.count; ++i) out.mesh.vertices[i] = vertexPosition(xyz, i, path);
  out.vertexAttributes = vertexAttributesOf(vertex);

  out.mesh.triangles.reserve(face.count);
  for (std::size_t f = 0; f < face.count; ++f) {
    const std::size_t begin = indices->listStarts[f];
    const std::size_t end = indices->listStarts[f + 1];
    if (end - begin < 3)
      throw InputError(path.string() + ": PLY face " + std::to_string(f) + " has " + std::to_string(end - begin) +
                       " vertices, expected at least 3");
    for (std::size_t k = begin; k < end; ++k) {
      const double v = indices->values[k];
      if (v < 0 || v >= static_cast<double>(vertex.count) || v != std::floor(v))
        throw InputError(path.string() + ": PLY face " + std::to_string(f) + " refers to vertex " +
                         std::to_string(static_cast<long long>(v)) + ", expected an index below " +
                         std::to_string(vertex.count));
    }
    // Fan triangulation: exact for the convex polygons PLY exporters write.
    const auto at = [&](std::size_t k) { return static_cast<int>(indices->values[k]); };
    for (std::size_t k = begin + 1; k + 1 < end; ++k) out.mesh.triangles.push_back({at(begin), at(k), at(k + 1)});
  }
  return out;
}

}  // namespace msim::io
