#include "app/config/terrain_file.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "app/config/config.hpp"
#include "app/config/embedded.hpp"

namespace marionette {

namespace {

// Limits that keep a bad file from asking for absurd memory or query cost.
constexpr std::int64_t kMaxGridSide = 4096;
constexpr std::size_t kMaxFeatures = 65536;

int line_of(const toml::node& node) { return static_cast<int>(node.source().begin.line); }

std::string format_float(float v) {
    char buf[64];
    const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
    (void)ec;
    std::string s(buf, end);
    if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
    return s;
}

struct Reader {
    const std::string& file;
    const std::string& prefix;

    [[noreturn]] void fail(const toml::node& node, const std::string& key, const std::string& message) const {
        throw ConfigError(file, line_of(node), prefix + key, message);
    }

    float number(const toml::node& node, const std::string& key) const {
        double v = 0.0;
        if (const auto* f = node.as_floating_point()) v = f->get();
        else if (const auto* i = node.as_integer()) v = static_cast<double>(i->get());
        else fail(node, key, "expected a number (metres)");
        if (!std::isfinite(v) || std::fabs(v) > 1e6) fail(node, key, "expected a finite number within ±1e6");
        return static_cast<float>(v);
    }

    const toml::node& required(const toml::table& t, const std::string& table_key, const char* key) const {
        const toml::node* n = t.get(key);
        if (!n) fail(t, table_key + "." + key, "missing (expected a number)");
        return *n;
    }

    float number_key(const toml::table& t, const std::string& table_key, const char* key) const {
        return number(required(t, table_key, key), table_key + "." + key);
    }

    // [x, z] pairs.
    void pair(const toml::table& t, const std::string& table_key, const char* key, float& x, float& z) const {
        const toml::node& n = required(t, table_key, key);
        const toml::array* a = n.as_array();
        if (!a || a->size() != 2) fail(n, table_key + "." + key, "expected an array of two numbers [x, z]");
        x = number(*a->get(0), table_key + "." + key);
        z = number(*a->get(1), table_key + "." + key);
    }

    void only_keys(const toml::table& t, const std::string& table_key, std::initializer_list<const char*> keys) const {
        for (const auto& [k, node] : t) {
            bool known = false;
            for (const char* name : keys) known = known || k.str() == name;
            if (!known) {
                std::string list;
                for (const char* name : keys) list += (list.empty() ? "" : ", ") + std::string(name);
                fail(node, table_key + "." + std::string(k.str()), "unknown key (expected one of: " + list + ")");
            }
        }
    }

    void footprint(const toml::table& t, const std::string& table_key, float& min_x, float& min_z, float& max_x, float& max_z) const {
        pair(t, table_key, "min", min_x, min_z);
        pair(t, table_key, "max", max_x, max_z);
        if (!(max_x > min_x) || !(max_z > min_z))
            fail(*t.get("max"), table_key + ".max", "must be greater than min in both x and z");
    }

    const toml::array& array_of_tables(const toml::node& n, const std::string& key) const {
        const toml::array* a = n.as_array();
        if (!a || !a->is_array_of_tables()) fail(n, key, "expected an array of tables ([[" + prefix + key + "]])");
        if (a->size() > kMaxFeatures) fail(n, key, "too many entries (at most 65536)");
        return *a;
    }
};

Heightfield read_heightfield(const Reader& r, const toml::node& node) {
    const toml::table* t = node.as_table();
    if (!t) r.fail(node, "heightfield", "expected a table ([" + r.prefix + "heightfield])");
    r.only_keys(*t, "heightfield", {"origin", "cell", "size", "heights"});
    Heightfield hf;
    r.pair(*t, "heightfield", "origin", hf.origin_x, hf.origin_z);
    hf.cell = r.number_key(*t, "heightfield", "cell");
    if (!(hf.cell > 0.0f)) r.fail(*t->get("cell"), "heightfield.cell", "must be positive (metres between grid points)");
    const toml::node& size_node = r.required(*t, "heightfield", "size");
    const toml::array* size = size_node.as_array();
    if (!size || size->size() != 2 || !size->get(0)->is_integer() || !size->get(1)->is_integer())
        r.fail(size_node, "heightfield.size", "expected two integers [nx, nz]");
    const std::int64_t nx = size->get(0)->as_integer()->get();
    const std::int64_t nz = size->get(1)->as_integer()->get();
    if (nx < 2 || nz < 2 || nx > kMaxGridSide || nz > kMaxGridSide)
        r.fail(size_node, "heightfield.size", "each side must be an integer in [2, 4096]");
    hf.nx = static_cast<std::int32_t>(nx);
    hf.nz = static_cast<std::int32_t>(nz);
    const toml::node& heights_node = r.required(*t, "heightfield", "heights");
    const toml::array* heights = heights_node.as_array();
    const std::size_t count = static_cast<std::size_t>(nx * nz);
    if (!heights || heights->size() != count)
        r.fail(heights_node, "heightfield.heights",
               "expected an array of nx × nz = " + std::to_string(count) + " numbers (row-major, z then x)");
    hf.heights.reserve(count);
    for (const toml::node& h : *heights) hf.heights.push_back(r.number(h, "heightfield.heights"));
    return hf;
}

}  // namespace

bool table_has_terrain_data(const toml::table& table) {
    return table.contains("heightfield") || table.contains("box") || table.contains("slope");
}

Terrain terrain_from_table(const toml::table& table, const std::string& file, const std::string& prefix) {
    const Reader r{file, prefix};
    Terrain terrain;
    for (const auto& [key, node] : table) {
        const std::string k(key.str());
        if (k == "heightfield") {
            terrain.heightfield = read_heightfield(r, node);
        } else if (k == "box") {
            for (const toml::node& entry : r.array_of_tables(node, "box")) {
                const toml::table& t = *entry.as_table();
                r.only_keys(t, "box", {"min", "max", "top"});
                TerrainBox b;
                r.footprint(t, "box", b.min_x, b.min_z, b.max_x, b.max_z);
                b.top = r.number_key(t, "box", "top");
                terrain.boxes.push_back(b);
            }
        } else if (k == "slope") {
            for (const toml::node& entry : r.array_of_tables(node, "slope")) {
                const toml::table& t = *entry.as_table();
                r.only_keys(t, "slope", {"min", "max", "base", "grade"});
                TerrainSlope s;
                r.footprint(t, "slope", s.min_x, s.min_z, s.max_x, s.max_z);
                s.base = r.number_key(t, "slope", "base");
                r.pair(t, "slope", "grade", s.grade_x, s.grade_z);
                if (std::fabs(s.grade_x) > 2.0f || std::fabs(s.grade_z) > 2.0f)
                    r.fail(*t.get("grade"), "slope.grade", "each grade (rise/run) must be within ±2 (about ±63°)");
                terrain.slopes.push_back(s);
            }
        } else if (k != "name") {
            r.fail(node, k, "unknown key (expected one of: name, heightfield, box, slope)");
        }
    }
    return terrain;
}

Terrain parse_terrain_text(std::string_view text, const std::string& file) {
    toml::table doc;
    try {
        doc = toml::parse(text, file);
    } catch (const toml::parse_error& e) {
        throw ConfigError(file, static_cast<int>(e.source().begin.line), "", "TOML syntax error: " + std::string(e.description()));
    }
    return terrain_from_table(doc, file, "");
}

std::string builtin_terrain_list() {
    std::string list;
    for (const char* name : kBuiltinTerrains) list += (list.empty() ? "" : ", ") + std::string(name);
    return list;
}

Terrain load_terrain(const std::string& spec) {
    std::string name = spec;
    if (name.rfind("builtin:", 0) == 0) name = name.substr(8);
    for (const char* builtin : kBuiltinTerrains)
        if (name == builtin) {
            const std::string path = "config/terrain/" + name + ".toml";
            return parse_terrain_text(embedded::find(path), path);
        }
    if (spec.rfind("builtin:", 0) == 0)
        throw ConfigError(spec, 0, "", "no built-in terrain named '" + name + "' (expected one of " + builtin_terrain_list() + ")");
    std::ifstream in(spec, std::ios::binary);
    if (!in) throw ConfigError(spec, 0, "", "cannot open the terrain file (expected a path or one of " + builtin_terrain_list() + ")");
    std::ostringstream ss;
    ss << in.rdbuf();
    return parse_terrain_text(ss.str(), spec);
}

std::string serialize_terrain(const Terrain& t, const std::string& prefix) {
    std::string out;
    const Heightfield& hf = t.heightfield;
    if (hf.nx >= 2 && hf.nz >= 2) {
        out += "\n[" + prefix + "heightfield]\n";
        out += "origin = [" + format_float(hf.origin_x) + ", " + format_float(hf.origin_z) + "]\n";
        out += "cell = " + format_float(hf.cell) + "\n";
        out += "size = [" + std::to_string(hf.nx) + ", " + std::to_string(hf.nz) + "]\n";
        out += "heights = [";
        for (std::size_t i = 0; i < hf.heights.size(); ++i)
            out += (i == 0 ? "" : (i % static_cast<std::size_t>(hf.nx) == 0 ? ",\n  " : ", ")) + format_float(hf.heights[i]);
        out += "]\n";
    }
    for (const TerrainBox& b : t.boxes)
        out += "\n[[" + prefix + "box]]\nmin = [" + format_float(b.min_x) + ", " + format_float(b.min_z) + "]\nmax = [" +
               format_float(b.max_x) + ", " + format_float(b.max_z) + "]\ntop = " + format_float(b.top) + "\n";
    for (const TerrainSlope& s : t.slopes)
        out += "\n[[" + prefix + "slope]]\nmin = [" + format_float(s.min_x) + ", " + format_float(s.min_z) + "]\nmax = [" +
               format_float(s.max_x) + ", " + format_float(s.max_z) + "]\nbase = " + format_float(s.base) +
               "\ngrade = [" + format_float(s.grade_x) + ", " + format_float(s.grade_z) + "]\n";
    return out;
}

}  // namespace marionette
