#include "io/tensor_file.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <optional>

#include "core/error.h"

namespace facetfit {

namespace {

// Tensor file layout (little-endian), as written by RGL's tools and read by Mitsuba's TensorFile:
//   "tensor_file\0" (12 bytes), version major, minor (1 byte each), field count (uint32), then per
//   field: name length (uint16), name, rank (uint16), dtype (uint8), data offset from the start of
//   the file (uint64), extent of each dimension (uint64 each). The arrays follow the table.
constexpr char kMagic[12] = {'t', 'e', 'n', 's', 'o', 'r', '_', 'f', 'i', 'l', 'e', '\0'};
constexpr std::size_t kPreamble = 12 + 2 + 4;
// Smallest possible table entry: a one-character name, rank 1.
constexpr std::size_t kMinFieldEntry = 2 + 1 + 2 + 1 + 8 + 8;
constexpr unsigned kMaxRank = 8;

std::size_t dtype_bytes(std::uint8_t dtype) {
  static constexpr std::size_t kBytes[] = {0, 1, 1, 2, 2, 4, 4, 8, 8, 2, 4, 8};
  return dtype < std::size(kBytes) ? kBytes[dtype] : 0;
}

const char* dtype_name(std::uint8_t dtype) {
  static constexpr const char* kNames[] = {"invalid", "uint8",  "int8",   "uint16",  "int16",   "uint32",
                                           "int32",   "uint64", "int64",  "float16", "float32", "float64"};
  return dtype < std::size(kNames) ? kNames[dtype] : "unknown";
}

// Bounded little-endian reads of the header; running off the end is a truncated header.
class HeaderCursor {
 public:
  HeaderCursor(const std::string& path, const std::vector<unsigned char>& bytes) : path_(path), bytes_(bytes) {}

  std::uint64_t uint(std::size_t width, const std::string& what) {
    need(width, what);
    std::uint64_t v = 0;
    for (std::size_t k = 0; k < width; ++k) v |= std::uint64_t(bytes_[pos_ + k]) << (8 * k);
    pos_ += width;
    return v;
  }

  std::string text(std::size_t length, const std::string& what) {
    need(length, what);
    std::string s(reinterpret_cast<const char*>(bytes_.data() + pos_), length);
    pos_ += length;
    return s;
  }

  std::size_t pos() const { return pos_; }

 private:
  void need(std::size_t width, const std::string& what) const {
    if (width > bytes_.size() - pos_)
      fail(path_, "truncated header: " + what + " at byte " + std::to_string(pos_) + " runs past the end of the file (" +
                      std::to_string(bytes_.size()) + " bytes)");
  }

  const std::string& path_;
  const std::vector<unsigned char>& bytes_;
  std::size_t pos_ = 0;
};

// The 14 bytes before the field count: the magic string and version 1.0.
void check_preamble(const std::string& path, const std::vector<unsigned char>& bytes) {
  if (bytes.size() < kPreamble)
    fail(path, "truncated header (" + std::to_string(bytes.size()) + " bytes; a tensor file starts with an " +
                   std::to_string(kPreamble) + "-byte preamble)");
  if (std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    fail(path, "not a tensor file (the first 12 bytes are not \"tensor_file\\0\")");
  if (bytes[12] != 1 || bytes[13] != 0)
    fail(path, "unsupported tensor file version " + std::to_string(bytes[12]) + "." + std::to_string(bytes[13]) +
                   " (this reader knows 1.0)");
}

// The number of fields, at least one and no more than the file's bytes could describe.
std::uint64_t read_field_count(HeaderCursor& in, const std::string& path, std::size_t file_bytes) {
  const std::uint64_t n_fields = in.uint(4, "field count");
  if (n_fields == 0) fail(path, "tensor file has no fields");
  if (n_fields > (file_bytes - kPreamble) / kMinFieldEntry)
    fail(path, "header claims " + std::to_string(n_fields) + " fields, more than a file of " + std::to_string(file_bytes) +
                   " bytes can describe (truncated, or a corrupt count)");
  return n_fields;
}

// A field's name: not empty, and printable, since names go into error messages, which must stay one
// printable line. `entry` names the table entry in messages.
std::string read_field_name(HeaderCursor& in, const std::string& path, const std::string& entry) {
  const std::size_t name_length = static_cast<std::size_t>(in.uint(2, entry));
  if (name_length == 0) fail(path, entry + " has an empty name");
  const std::string name = in.text(name_length, entry);
  for (const char ch : name)
    if (ch < 0x20 || ch > 0x7e) fail(path, entry + " has a name with non-printable bytes");
  return name;
}

// The product of a shape's extents, or nothing where it overflows 64 bits.
std::optional<std::uint64_t> element_count(const std::vector<std::uint64_t>& shape) {
  std::uint64_t count = 1;
  for (const std::uint64_t n : shape) {
    if (n != 0 && count > std::numeric_limits<std::uint64_t>::max() / n) return std::nullopt;
    count *= n;
  }
  return count;
}

// The rest of a field's entry after its name: rank, dtype, offset and shape, with its element count and
// byte size computed without overflow. `what` names the field in messages.
TensorField read_field(HeaderCursor& in, const std::string& path, const std::string& what) {
  TensorField f;
  const std::uint64_t rank = in.uint(2, what);
  f.dtype = static_cast<std::uint8_t>(in.uint(1, what));
  f.offset = in.uint(8, what);
  if (rank == 0 || rank > kMaxRank)
    fail(path, what + " claims " + std::to_string(rank) + " dimensions (expected 1 to " + std::to_string(kMaxRank) + ")");
  const std::size_t elem = dtype_bytes(f.dtype);
  if (elem == 0) fail(path, what + " has unknown dtype " + std::to_string(f.dtype));
  for (std::uint64_t d = 0; d < rank; ++d) f.shape.push_back(in.uint(8, what));

  // Element count and byte size without overflow: both must fit in the file.
  const std::optional<std::uint64_t> count = element_count(f.shape);
  if (!count || *count > (std::numeric_limits<std::uint64_t>::max() / elem))
    fail(path, what + " has impossible dimensions " + tensor_shape_string(f.shape) + " (size overflows)");
  f.count = static_cast<std::size_t>(std::min<std::uint64_t>(*count, std::numeric_limits<std::size_t>::max()));
  f.bytes = *count * elem;
  return f;
}

// Every field's data lies inside the file and after the field table, which ends at byte `table_end`.
// Checked only once the whole table has been read, so that a file cut inside the table reads as a
// truncated header rather than as some field's missing data.
void check_field_extents(const std::string& path, std::size_t file_bytes, std::size_t table_end,
                         const std::map<std::string, TensorField>& fields) {
  for (const auto& [name, f] : fields) {
    if (f.offset > file_bytes || f.bytes > file_bytes - f.offset)
      fail(path, "field '" + name + "' (" + tensor_shape_string(f.shape) + " " + dtype_name(f.dtype) + ", " +
                     std::to_string(f.bytes) + " bytes at offset " + std::to_string(f.offset) +
                     ") extends past the end of the file (" + std::to_string(file_bytes) + " bytes; truncated?)");
    if (f.offset < table_end && f.bytes > 0)
      fail(path, "field '" + name + "' at offset " + std::to_string(f.offset) + " overlaps the field table (which ends at byte " +
                     std::to_string(table_end) + ")");
  }
}

// Reads the field table, checking every extent against the file before anything trusts it.
std::map<std::string, TensorField> parse_header(const std::string& path, const std::vector<unsigned char>& bytes) {
  check_preamble(path, bytes);
  HeaderCursor in(path, bytes);
  in.text(14, "preamble");
  const std::uint64_t n_fields = read_field_count(in, path, bytes.size());
  std::map<std::string, TensorField> fields;
  for (std::uint64_t k = 0; k < n_fields; ++k) {
    const std::string entry = "entry " + std::to_string(k) + " of the field table";
    const std::string name = read_field_name(in, path, entry);
    const std::string what = "field '" + name + "'";
    if (!fields.emplace(name, read_field(in, path, what)).second) fail(path, what + " appears twice in the field table");
  }
  check_field_extents(path, bytes.size(), in.pos(), fields);
  return fields;
}

}  // namespace

std::string tensor_shape_string(const std::vector<std::uint64_t>& shape) {
  std::string s;
  for (std::size_t k = 0; k < shape.size(); ++k) s += (k ? " x " : "") + std::to_string(shape[k]);
  return s.empty() ? "(scalar)" : s;
}

TensorFile::TensorFile(const std::string& path, const std::vector<unsigned char>& bytes)
    : path_(path), bytes_(bytes), fields_(parse_header(path, bytes)) {}

const TensorField& TensorFile::get(const std::string& name, std::uint8_t dtype, std::size_t rank) const {
  const auto it = fields_.find(name);
  if (it == fields_.end()) fail(path_, "required field '" + name + "' is missing");
  const TensorField& f = it->second;
  if (f.dtype != dtype)
    fail(path_, "field '" + name + "' is " + dtype_name(f.dtype) + ", expected " + dtype_name(dtype));
  if (f.shape.size() != rank)
    fail(path_, "field '" + name + "' has shape " + tensor_shape_string(f.shape) + ", expected " + std::to_string(rank) +
                    " dimension" + (rank == 1 ? "" : "s"));
  return f;
}

std::vector<double> TensorFile::floats(const std::string& name, const TensorField& f) const {
  std::vector<double> out(f.count);
  const unsigned char* p = bytes_.data() + f.offset;
  for (std::size_t k = 0; k < f.count; ++k, p += 4) {
    const std::uint32_t bits = std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
                               std::uint32_t(p[3]) << 24;
    float v;
    std::memcpy(&v, &bits, sizeof v);
    if (!std::isfinite(v))
      fail(path_, "field '" + name + "' has " + (std::isnan(v) ? "a NaN" : "an infinity") + " at element " +
                      std::to_string(k) + " (byte offset " + std::to_string(f.offset + 4 * k) + ")");
    out[k] = double(v);
  }
  return out;
}

void TensorFile::check(bool ok, const std::string& problem) const {
  if (!ok) fail(path_, problem);
}

}  // namespace facetfit
