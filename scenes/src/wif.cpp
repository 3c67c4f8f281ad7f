#include "weft/scenes/wif.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <unordered_set>

#include "weft/core/error.h"
#include "weft/core/params.h"

namespace weft {
namespace {

struct Entry {
  std::string key;    // upper case, as written otherwise
  std::string value;  // trimmed
  int line = 0;
};
struct Section {
  std::vector<Entry> entries;
  std::unordered_set<std::string> keys;  // of 'entries': a duplicate found in constant time
  int line = 0;
};

std::string trim(std::string_view s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return std::string(s.substr(a, b - a));
}

// Upper case with runs of blanks folded to one space: "Warp  colors" -> "WARP COLORS".
std::string normalize_name(std::string_view s) {
  std::string out;
  for (char c : trim(s)) {
    if (std::isspace(static_cast<unsigned char>(c))) {
      if (!out.empty() && out.back() != ' ') out += ' ';
    } else {
      out += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    }
  }
  return out;
}

class Draft {
 public:
  Draft(std::string_view text, std::string source) : source_(std::move(source)) { split(text); }

  [[noreturn]] void fail(const std::string& section, const std::string& key,
                         const std::string& msg) const {
    throw Error(source_, key.empty() ? "[" + section + "]" : "[" + section + "] " + key, msg);
  }

  const Section* section(const std::string& name) const {
    const auto it = sections_.find(name);
    return it == sections_.end() ? nullptr : &it->second;
  }
  const Section& required(const std::string& name, const std::string& why) const {
    const Section* s = section(name);
    if (!s) throw Error(source_, "[" + name + "]", "section is missing (" + why + ")");
    return *s;
  }
  std::optional<std::string> value(const std::string& sec, const std::string& key) const {
    const Section* s = section(sec);
    if (!s) return std::nullopt;
    for (const Entry& e : s->entries)
      if (e.key == key) return e.value;
    return std::nullopt;
  }

  long long integer(const std::string& sec, const std::string& key, const std::string& text,
                    long long lo, long long hi) const {
    long long v = 0;
    const std::string t = trim(text);
    const char* end = t.data() + t.size();
    const auto r = std::from_chars(t.data(), end, v);
    if (t.empty() || r.ec != std::errc() || r.ptr != end)
      fail(sec, key, "'" + t + "' is not an integer");
    if (v < lo || v > hi)
      fail(sec, key,
           std::to_string(v) + " is out of range [" + std::to_string(lo) + ", " +
               std::to_string(hi) + "]");
    return v;
  }
  double number(const std::string& sec, const std::string& key, const std::string& text, double lo,
                double hi) const {
    double v = 0;
    const std::string t = trim(text);
    const char* end = t.data() + t.size();
    const auto r = std::from_chars(t.data(), end, v);
    if (t.empty() || r.ec != std::errc() || r.ptr != end || !std::isfinite(v))
      fail(sec, key, "'" + t + "' is not a number");
    if (!(v >= lo && v <= hi))
      fail(sec, key,
           t + " is out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v;
  }
  bool boolean(const std::string& sec, const std::string& key, const std::string& text) const {
    const std::string t = normalize_name(text);
    if (t == "YES" || t == "TRUE" || t == "ON" || t == "1") return true;
    if (t == "NO" || t == "FALSE" || t == "OFF" || t == "0") return false;
    fail(sec, key, "'" + trim(text) + "' is not a boolean (yes/no, true/false, on/off, 1/0)");
  }
  // Comma-separated integers in [lo, hi]; an empty value is an empty list. Bounded by 'max_items'.
  std::vector<int> int_list(const std::string& sec, const std::string& key, const std::string& text,
                            int lo, int hi) const {
    std::vector<int> out;
    if (trim(text).empty()) return out;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
      if (static_cast<int>(out.size()) >= hi)
        fail(sec, key, "lists more than " + std::to_string(hi) + " items");
      out.push_back(static_cast<int>(integer(sec, key, item, lo, hi)));
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  // The entries "index=value" of a per-thread section, each index in [1, n] at most once.
  // Returns (index - 1, entry) pairs; 'require_all' demands every index.
  std::vector<std::pair<int, const Entry*>> indexed(const std::string& sec, int n,
                                                    bool require_all) const {
    const Section* s = section(sec);
    std::vector<std::pair<int, const Entry*>> out;
    if (!s) return out;
    if (s->entries.size() > static_cast<size_t>(n))
      fail(sec, "",
           "has " + std::to_string(s->entries.size()) + " entries for " + std::to_string(n) +
               " indices");
    std::vector<uint8_t> seen(static_cast<size_t>(n), 0);
    for (const Entry& e : s->entries) {
      const int i = static_cast<int>(integer(sec, e.key, e.key, 1, n)) - 1;
      if (seen[i]) fail(sec, e.key, "index appears twice");
      seen[i] = 1;
      out.emplace_back(i, &e);
    }
    if (require_all)
      for (int i = 0; i < n; ++i)
        if (!seen[i]) fail(sec, std::to_string(i + 1), "index is missing");
    return out;
  }

  const std::string& source() const { return source_; }

 private:
  void split(std::string_view text) {
    std::string current;
    int line_no = 0;
    size_t pos = 0;
    while (pos <= text.size()) {
      size_t nl = text.find('\n', pos);
      if (nl == std::string_view::npos) nl = text.size();
      const std::string line = trim(text.substr(pos, nl - pos));
      pos = nl + 1;
      ++line_no;
      if (line.empty() || line[0] == ';') continue;
      if (line.front() == '[') {
        if (line.back() != ']')
          throw Error(source_, "line " + std::to_string(line_no), "unterminated section name");
        current = normalize_name(std::string_view(line).substr(1, line.size() - 2));
        if (sections_.count(current))
          throw Error(source_, "[" + current + "]", "section appears twice");
        if (sections_.size() >= kWifMaxSections)
          throw Error(source_, "[" + current + "]",
                      "more than " + std::to_string(kWifMaxSections) + " sections");
        sections_[current].line = line_no;
        continue;
      }
      const auto eq = line.find('=');
      if (current.empty() || eq == std::string::npos)
        throw Error(source_, "line " + std::to_string(line_no),
                    current.empty() ? "text before the first [SECTION]"
                                    : "expected KEY=VALUE in [" + current + "]");
      Entry e{normalize_name(std::string_view(line).substr(0, eq)), trim(line.substr(eq + 1)),
              line_no};
      Section& s = sections_[current];
      const bool section_full = s.entries.size() >= kWifMaxSectionKeys;
      if (section_full || ++keys_ > kWifMaxKeys)
        throw Error(source_, "[" + current + "] " + e.key,
                    section_full
                        ? "more than " + std::to_string(kWifMaxSectionKeys) + " keys in the section"
                        : "more than " + std::to_string(kWifMaxKeys) + " keys in the file");
      if (!s.keys.insert(e.key).second)
        throw Error(source_, "[" + current + "] " + e.key, "key appears twice");
      s.entries.push_back(std::move(e));
    }
  }

  std::string source_;
  std::map<std::string, Section> sections_;
  size_t keys_ = 0;  // over every section
};

double unit_mm(const Draft& d, const std::string& sec) {
  const auto u = d.value(sec, "UNITS");
  if (!u) return 0;  // checked where a length needs it
  const std::string v = normalize_name(*u);
  if (v == "DECIPOINTS") return 25.4 / 720.0;  // a decipoint is a tenth of a 1/72 inch point
  if (v == "INCHES") return 25.4;
  if (v == "CENTIMETERS" || v == "CENTIMETRES") return 10.0;
  if (v == "MILLIMETERS" || v == "MILLIMETRES") return 1.0;
  d.fail(sec, "UNITS", "'" + *u + "' is not one of Decipoints, Inches, Centimeters, Millimeters");
}

struct Palette {
  double lo = 0, hi = 255;
  std::map<int, std::array<double, 3>> colors;
};

Palette read_palette(const Draft& d) {
  Palette p;
  if (const auto r = d.value("COLOR PALETTE", "RANGE")) {
    const auto comma = r->find(',');
    if (comma == std::string::npos) d.fail("COLOR PALETTE", "RANGE", "expected LO,HI");
    p.lo = d.number("COLOR PALETTE", "RANGE", r->substr(0, comma), -1e9, 1e9);
    p.hi = d.number("COLOR PALETTE", "RANGE", r->substr(comma + 1), -1e9, 1e9);
    if (!(p.hi > p.lo)) d.fail("COLOR PALETTE", "RANGE", "needs LO < HI");
  }
  int entries = 1 << 16;
  if (const auto e = d.value("COLOR PALETTE", "ENTRIES"))
    entries = static_cast<int>(d.integer("COLOR PALETTE", "ENTRIES", *e, 0, 1 << 16));
  for (const auto& [i, e] : d.indexed("COLOR TABLE", entries, false)) {
    std::array<double, 3> rgb{};
    std::stringstream ss(e->value);
    std::string item;
    int k = 0;
    while (std::getline(ss, item, ',')) {
      if (k >= 3) d.fail("COLOR TABLE", e->key, "expected R,G,B");
      rgb[k++] = (d.number("COLOR TABLE", e->key, item, p.lo, p.hi) - p.lo) / (p.hi - p.lo);
    }
    if (k != 3) d.fail("COLOR TABLE", e->key, "expected R,G,B");
    p.colors[i + 1] = rgb;
  }
  return p;
}

std::array<double, 3> palette_color(const Draft& d, const Palette& p, const std::string& sec,
                                    const std::string& key, const std::string& text) {
  const int idx = static_cast<int>(d.integer(sec, key, text, 1, 1 << 16));
  const auto it = p.colors.find(idx);
  if (it == p.colors.end())
    d.fail(sec, key, "colour " + std::to_string(idx) + " is not in [COLOR TABLE]");
  return it->second;
}

// [WARP] or [WEFT]: thread count, default spacing/thickness/colour, per-thread overrides.
std::vector<WifThread> read_threads(const Draft& d, const std::string& dir, const Palette& pal) {
  d.required(dir, "thread count and sizes");
  const auto threads = d.value(dir, "THREADS");
  if (!threads) d.fail(dir, "THREADS", "is required");
  const int n = static_cast<int>(d.integer(dir, "THREADS", *threads, 1, kWifMaxThreads));
  const double mm = unit_mm(d, dir);
  auto length = [&](const std::string& sec, const std::string& key, const std::string& text) {
    if (mm == 0) d.fail(dir, "UNITS", "is required when lengths are given");
    const double v = mm * d.number(sec, key, text, 1e-9, 1e9);
    if (v < kWifMinThreadMm)
      d.fail(sec, key,
             trim(text) + " (" + ParamReader::fmt(v * 1e3) + " um) is thinner than one fiber (" +
                 ParamReader::fmt(kWifMinThreadMm * 1e3) +
                 " um; the finest textile fibers are a few um across)");
    return v;
  };
  WifThread base;
  if (const auto v = d.value(dir, "SPACING")) base.spacing_mm = length(dir, "SPACING", *v);
  if (const auto v = d.value(dir, "THICKNESS")) base.thickness_mm = length(dir, "THICKNESS", *v);
  if (const auto v = d.value(dir, "COLOR")) {
    if (v->find(',') == std::string::npos) {
      base.rgb = palette_color(d, pal, dir, "COLOR", *v);
    } else {
      std::stringstream ss(*v);
      std::string item;
      int k = 0;
      while (std::getline(ss, item, ',')) {
        if (k >= 3) d.fail(dir, "COLOR", "expected an index or R,G,B");
        base.rgb[k++] = (d.number(dir, "COLOR", item, pal.lo, pal.hi) - pal.lo) / (pal.hi - pal.lo);
      }
      if (k != 3) d.fail(dir, "COLOR", "expected an index or R,G,B");
    }
  }
  std::vector<WifThread> out(static_cast<size_t>(n), base);  // n checked above
  for (const auto& [i, e] : d.indexed(dir + " SPACING", n, false))
    out[i].spacing_mm = length(dir + " SPACING", e->key, e->value);
  for (const auto& [i, e] : d.indexed(dir + " THICKNESS", n, false))
    out[i].thickness_mm = length(dir + " THICKNESS", e->key, e->value);
  for (const auto& [i, e] : d.indexed(dir + " COLORS", n, false))
    out[i].rgb = palette_color(d, pal, dir + " COLORS", e->key, e->value);
  return out;
}

}  // namespace

WifDraft parse_wif(std::string_view text, const std::string& source) {
  if (text.size() > kWifMaxFileBytes) throw Error(source, "", "file is larger than 64 MiB");
  if (const size_t nul = text.find('\0'); nul != std::string_view::npos)
    throw Error(source,
                "line " + std::to_string(1 + std::count(text.begin(), text.begin() + nul, '\n')),
                "a NUL byte (at byte " + std::to_string(nul) + "): a WIF draft is a text file");
  const Draft d(text, source);
  WifDraft w;
  w.source = source;
  d.required("WEAVING", "shafts and treadles");
  const auto shafts = d.value("WEAVING", "SHAFTS");
  if (!shafts) d.fail("WEAVING", "SHAFTS", "is required");
  w.shafts = static_cast<int>(d.integer("WEAVING", "SHAFTS", *shafts, 1, kWifMaxShafts));
  if (const auto r = d.value("WEAVING", "RISING SHED"))
    w.rising_shed = d.boolean("WEAVING", "RISING SHED", *r);

  const Palette pal = read_palette(d);
  // Both counts are checked (read_threads) before the matrix size is; the product bounds memory.
  const auto warp_n = d.value("WARP", "THREADS"), weft_n = d.value("WEFT", "THREADS");
  if (warp_n && weft_n) {
    const double cells =
        static_cast<double>(d.integer("WARP", "THREADS", *warp_n, 1, kWifMaxThreads)) *
        static_cast<double>(d.integer("WEFT", "THREADS", *weft_n, 1, kWifMaxThreads));
    if (cells > kWifMaxCells)
      d.fail("WARP", "THREADS",
             "warp threads x picks = " + std::to_string(cells) +
                 " exceeds the limit of 2e7 crossings");
  }
  w.warp = read_threads(d, "WARP", pal);
  w.weft = read_threads(d, "WEFT", pal);
  w.colours_given = d.value("WARP", "COLOR") || d.value("WEFT", "COLOR") ||
                    d.section("WARP COLORS") || d.section("WEFT COLORS");
  const int nwarp = static_cast<int>(w.warp.size()), nweft = static_cast<int>(w.weft.size());

  d.required("THREADING", "which shaft each warp thread is on");
  for (const auto& [i, e] : d.indexed("THREADING", nwarp, true))
    w.warp[i].shafts = d.int_list("THREADING", e->key, e->value, 1, w.shafts);

  if (d.section("LIFTPLAN")) {
    w.weft_source = "LIFTPLAN";
    for (const auto& [j, e] : d.indexed("LIFTPLAN", nweft, true))
      w.weft[j].shafts = d.int_list("LIFTPLAN", e->key, e->value, 1, w.shafts);
  } else {
    w.weft_source = "TREADLING";
    d.required("TREADLING", "or [LIFTPLAN]: which shafts each pick lifts");
    d.required("TIEUP", "which shafts each treadle lifts");
    const auto treadles = d.value("WEAVING", "TREADLES");
    if (!treadles) d.fail("WEAVING", "TREADLES", "is required with [TREADLING]");
    w.treadles = static_cast<int>(d.integer("WEAVING", "TREADLES", *treadles, 1, kWifMaxShafts));
    std::vector<std::vector<int>> tie(static_cast<size_t>(w.treadles));
    for (const auto& [t, e] : d.indexed("TIEUP", w.treadles, false))
      tie[t] = d.int_list("TIEUP", e->key, e->value, 1, w.shafts);
    // A pick lifts the union of its treadles' shafts: masks of shafts / 64 words, so a pick that
    // presses all 4096 treadles, each tied to all 4096 shafts, costs 4096 x 64 operations.
    const size_t words = static_cast<size_t>(w.shafts) / 64 + 1;
    std::vector<uint64_t> tie_mask(tie.size() * words, 0), mask(words);
    for (size_t t = 0; t < tie.size(); ++t)
      for (int s : tie[t]) tie_mask[t * words + s / 64] |= uint64_t{1} << (s % 64);
    for (const auto& [j, e] : d.indexed("TREADLING", nweft, true)) {
      std::fill(mask.begin(), mask.end(), 0);
      for (int t : d.int_list("TREADLING", e->key, e->value, 1, w.treadles))
        for (size_t k = 0; k < words; ++k) mask[k] |= tie_mask[(t - 1) * words + k];
      std::vector<int> lifted;
      for (int s = 1; s <= w.shafts; ++s)
        if (mask[s / 64] >> (s % 64) & 1) lifted.push_back(s);
      w.weft[j].shafts = std::move(lifted);
    }
  }
  return w;
}

WifDraft read_wif(const std::filesystem::path& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw Error(path.string(), "", "cannot read: " + ec.message());
  if (size > kWifMaxFileBytes) throw Error(path.string(), "", "file is larger than 64 MiB");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string(), "", "cannot open");
  std::string text(static_cast<size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(size));
  if (!in) throw Error(path.string(), "", "read failed");
  return parse_wif(text, path.string());
}

Interlacing WifDraft::interlacing() const {
  Interlacing m;
  m.warps = static_cast<int>(warp.size());
  m.wefts = static_cast<int>(weft.size());
  m.warp_over.assign(static_cast<size_t>(m.warps) * m.wefts, 0);  // bounded by parse_wif
  // Shaft sets as bit masks: a crossing costs shafts / 64 word operations, not one per listed
  // shaft (a draft may thread each of 2e7 crossings' warps on all 4096 shafts).
  const size_t words = static_cast<size_t>(shafts) / 64 + 1;
  std::vector<uint64_t> warp_mask(static_cast<size_t>(m.warps) * words, 0), lifted(words);
  for (int i = 0; i < m.warps; ++i)
    for (int s : warp[i].shafts) warp_mask[i * words + s / 64] |= uint64_t{1} << (s % 64);
  for (int j = 0; j < m.wefts; ++j) {
    std::fill(lifted.begin(), lifted.end(), 0);
    for (int s : weft[j].shafts) lifted[s / 64] |= uint64_t{1} << (s % 64);
    for (int i = 0; i < m.warps; ++i) {
      bool up = false;
      for (size_t w = 0; w < words && !up; ++w) up = (warp_mask[i * words + w] & lifted[w]) != 0;
      // Sinking shed: the listed shafts go down, the others make the face.
      m.warp_over[static_cast<size_t>(j) * m.warps + i] = (up == rising_shed) ? 1 : 0;
    }
  }
  // Every crossing on one side: no thread interlaces, the cloth is two loose layers.
  const auto first = m.warp_over.begin();
  if (!m.warp_over.empty() &&
      std::all_of(first, m.warp_over.end(), [&](uint8_t o) { return o == *first; }))
    throw Error(source, weft_source == "LIFTPLAN" ? "[LIFTPLAN]" : "[TIEUP]",
                std::string("no thread interlaces: every warp lies ") +
                    (*first ? "over" : "under") +
                    " every pick (with this [THREADING]), so the cloth would be two loose layers");
  return m;
}

}  // namespace weft
