// link_order: the order of the functions in lowlevel.elf's .text that --relax shrinks most.
//
// The linker turns a 4-byte call/jmp into a 2-byte rcall/rjmp only when the target lies within
// 4 KiB (-4096..+4094 bytes from the instruction's end). Which calls qualify depends on where
// each function lands, so the order of the input sections is worth 2 bytes a call. This program
// reads an UNRELAXED link of the image (its map and its disassembly), models the relaxation
// exactly (every call/jmp that reaches becomes 2 bytes, repeated until nothing changes, as ld
// does) and searches the order of the .text.* sections for the smallest image:
//   1. greedy passes: each section moved to its best place, until no move pays;
//   2. simulated annealing on moves of blocks of 1..4 sections (fixed seed and iteration count:
//      the same input gives the same order).
// Constraints: rcall/rjmp written by hand (in asm) must stay within reach, and so must every
// interrupt handler from the vector table: the step interrupts' rjmp is counted in
// kVectorEntryCycles (cmake/check_step_isr.cmake checks the linked table), and a step edge that
// waits for another interrupt's entry waits one cycle less when that entry is an rjmp too.
//
// Usage: link_order <map> <disassembly> <current text_order.ld> <out.ld> [iterations]
// tools/link_order.sh runs it on a build (docs/firmware.md, "Link order").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct Section {
    std::string name; // input section, e.g. .text._ZN2ll3Num3mulERKS0_
    std::string file; // object, e.g. libll_core.a(fixmath.cpp.obj)
    long addr = 0;    // in the unrelaxed link
    int size = 0;     // unrelaxed
    bool movable = false;
    int align = 2;
};

enum class Kind { Relaxable, Hard, Ignored };

struct Site {
    int src = 0, off = 0; // section and offset of the instruction (unrelaxed)
    int dst = 0, doff = 0;
    Kind kind = Kind::Relaxable;
};

std::vector<Section> g_sec;
std::vector<Site> g_site;
std::vector<std::vector<int>> g_by_src; // sites of each section by offset
std::vector<int> g_prefix, g_suffix;

bool starts_with(const std::string& s, const char* p) {
    return s.compare(0, strlen(p), p) == 0;
}

// One input section of the map, kept when it is not empty.
void add_section(const std::string& name, const std::string& addr, const std::string& size,
                 const std::string& file) {
    Section s;
    s.name = name;
    s.addr = std::strtol(addr.c_str(), nullptr, 16);
    s.size = static_cast<int>(std::strtol(size.c_str(), nullptr, 16));
    s.file = file;
    if (s.size > 0) g_sec.push_back(s);
}

// The .text output section's input sections, from a GNU ld map.
bool read_map(const char* path) {
    std::ifstream in(path);
    std::string line;
    bool inside = false;
    std::string pending; // a long name, alone on its line: address, size and file follow
    while (std::getline(in, line)) {
        if (!inside) {
            inside = starts_with(line, ".text ");
            continue;
        }
        if (!line.empty() && line[0] == '.') break; // the next output section
        std::istringstream ss(line);
        std::string first, second, third, fourth;
        ss >> first >> second >> third >> fourth;
        if (line.size() > 1 && line[0] == ' ' && line[1] == '.') {
            if (second.empty()) {
                pending = first;
                continue;
            }
            add_section(first, second, third, fourth);
        } else if (!pending.empty() && starts_with(first, "0x") && !third.empty()) {
            add_section(pending, first, second, third);
        }
        pending.clear();
    }
    std::sort(g_sec.begin(), g_sec.end(),
              [](const Section& a, const Section& b) { return a.addr < b.addr; });
    for (Section& s : g_sec) {
        s.movable = starts_with(s.name, ".text.");
        s.align = starts_with(s.name, ".progmem") ? 1 : 2;
    }
    return !g_sec.empty();
}

int section_at(long addr) {
    auto it = std::upper_bound(g_sec.begin(), g_sec.end(), addr,
                               [](long a, const Section& s) { return a < s.addr; });
    if (it == g_sec.begin()) return -1;
    --it;
    if (addr >= it->addr + it->size) return -1;
    return static_cast<int>(it - g_sec.begin());
}

// Every call, jmp, rcall and rjmp from one section into another, from `avr-objdump -d`.
bool read_disassembly(const char* path) {
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line)) {
        size_t colon = line.find(':');
        if (colon == std::string::npos || line.find('\t') == std::string::npos) continue;
        char* end = nullptr;
        long addr = std::strtol(line.c_str(), &end, 16);
        if (end != line.c_str() + colon) continue;
        std::string op;
        size_t at = std::string::npos;
        for (const char* o : {"\trcall\t", "\trjmp\t", "\tcall\t", "\tjmp\t"}) {
            at = line.find(o);
            if (at != std::string::npos) {
                op = std::string(o + 1, strlen(o) - 2);
                break;
            }
        }
        if (op.empty()) continue;
        size_t semi = line.find("; 0x", at);
        size_t operand = line.find("0x", at);
        size_t from = semi != std::string::npos ? semi + 2 : operand;
        if (from == std::string::npos) continue;
        long target = std::strtol(line.c_str() + from, nullptr, 16);
        int src = section_at(addr);
        if (src < 0 || starts_with(g_sec[static_cast<size_t>(src)].name, ".progmem")) continue;
        int dst = section_at(target);
        if (dst < 0 || dst == src) continue;
        Site s;
        s.src = src;
        s.off = static_cast<int>(addr - g_sec[static_cast<size_t>(src)].addr);
        s.dst = dst;
        s.doff = static_cast<int>(target - g_sec[static_cast<size_t>(dst)].addr);
        const std::string& sn = g_sec[static_cast<size_t>(src)].name;
        const std::string& dn = g_sec[static_cast<size_t>(dst)].name;
        if (sn == ".vectors") {
            // Every handler within rjmp reach: one cycle less of interrupt entry, which a step
            // edge may have to wait for (the receive interrupt's stub above all).
            s.kind = starts_with(dn, ".text.__vector_") ? Kind::Hard : Kind::Ignored;
        } else {
            s.kind = (op == "call" || op == "jmp") ? Kind::Relaxable : Kind::Hard;
        }
        g_site.push_back(s);
    }
    return true;
}

// The size of the image with the movable sections in `order`, relaxed as ld does; hard
// constraints broken count 1,000,000 bytes each.
long cost(const std::vector<int>& order) {
    static std::vector<int> seq, shrink, addr, site_addr;
    static std::vector<char> relaxed;
    seq.clear();
    seq.insert(seq.end(), g_prefix.begin(), g_prefix.end());
    seq.insert(seq.end(), order.begin(), order.end());
    seq.insert(seq.end(), g_suffix.begin(), g_suffix.end());
    shrink.assign(g_sec.size(), 0);
    addr.assign(g_sec.size(), 0);
    site_addr.assign(g_site.size(), 0);
    relaxed.assign(g_site.size(), 0);
    auto target_of = [&](const Site& s) {
        int before = 0;
        for (int u : g_by_src[static_cast<size_t>(s.dst)]) {
            if (g_site[static_cast<size_t>(u)].off >= s.doff) break;
            before += relaxed[static_cast<size_t>(u)];
        }
        return addr[static_cast<size_t>(s.dst)] + s.doff - 2 * before;
    };
    auto reaches = [](int from, int to) {
        int k = to - from - 2;
        return k >= -4096 && k <= 4094;
    };
    int end = 0;
    for (int pass = 0; pass < 32; ++pass) {
        int a = 0;
        for (int s : seq) {
            if (g_sec[static_cast<size_t>(s)].align == 2) a = (a + 1) & ~1;
            addr[static_cast<size_t>(s)] = a;
            a += g_sec[static_cast<size_t>(s)].size - 2 * shrink[static_cast<size_t>(s)];
        }
        end = a;
        for (size_t s = 0; s < g_sec.size(); ++s) {
            int before = 0;
            for (int t : g_by_src[s]) {
                site_addr[static_cast<size_t>(t)] =
                    addr[s] + g_site[static_cast<size_t>(t)].off - 2 * before;
                before += relaxed[static_cast<size_t>(t)];
            }
        }
        bool changed = false;
        for (size_t t = 0; t < g_site.size(); ++t) {
            const Site& s = g_site[t];
            if (relaxed[t] || s.kind != Kind::Relaxable) continue;
            if (reaches(site_addr[t], target_of(s))) {
                relaxed[t] = 1;
                ++shrink[static_cast<size_t>(s.src)];
                changed = true;
            }
        }
        if (!changed) break;
    }
    long broken = 0;
    for (size_t t = 0; t < g_site.size(); ++t) {
        if (g_site[t].kind == Kind::Hard && !reaches(site_addr[t], target_of(g_site[t]))) {
            ++broken;
        }
    }
    return end + 1000000L * broken;
}

// A linker-script pattern for one input section: *archive:member(section) or *object(section).
std::string pattern(const Section& s) {
    std::string file = s.file, out;
    size_t paren = file.find('(');
    if (paren != std::string::npos) {
        std::string archive = file.substr(0, paren);
        std::string member = file.substr(paren + 1, file.size() - paren - 2);
        size_t slash = archive.rfind('/');
        if (slash != std::string::npos) archive = archive.substr(slash + 1);
        out = "*" + archive + ":" + member;
    } else {
        size_t slash = file.rfind('/');
        out = "*" + (slash == std::string::npos ? file : file.substr(slash + 1));
    }
    return out + "(" + s.name + ")";
}

} // namespace

int main(int argc, char** argv) {
    if (argc < 5) {
        std::cerr
            << "usage: link_order <map> <disassembly> <text_order.ld> <out.ld> [iterations]\n";
        return 2;
    }
    if (!read_map(argv[1])) {
        std::cerr << "link_order: no .text input sections in " << argv[1] << "\n";
        return 1;
    }
    read_disassembly(argv[2]);
    long iterations = argc > 5 ? std::atol(argv[5]) : 3000000;
    g_by_src.assign(g_sec.size(), {});
    for (size_t t = 0; t < g_site.size(); ++t) {
        g_by_src[static_cast<size_t>(g_site[t].src)].push_back(static_cast<int>(t));
    }
    for (auto& v : g_by_src) {
        std::sort(v.begin(), v.end(), [](int a, int b) {
            return g_site[static_cast<size_t>(a)].off < g_site[static_cast<size_t>(b)].off;
        });
    }
    std::vector<int> order;
    for (size_t i = 0; i < g_sec.size(); ++i) {
        int s = static_cast<int>(i);
        if (g_sec[i].movable) {
            order.push_back(s);
        } else if (order.empty()) {
            g_prefix.push_back(s);
        } else {
            g_suffix.push_back(s);
        }
    }
    long start = cost(order), best = start;
    std::cerr << "link_order: " << order.size() << " sections, " << g_site.size()
              << " calls and jumps between them; modelled size " << start << " B\n";
    // 1. Greedy: each section to its best place.
    for (bool improved = true; improved;) {
        improved = false;
        for (int s : std::vector<int>(order)) {
            std::vector<int> rest = order;
            size_t from =
                static_cast<size_t>(std::find(rest.begin(), rest.end(), s) - rest.begin());
            rest.erase(rest.begin() + static_cast<long>(from));
            long bc = best;
            size_t bp = from;
            for (size_t p = 0; p <= rest.size(); ++p) {
                if (p == from) continue;
                std::vector<int> o = rest;
                o.insert(o.begin() + static_cast<long>(p), s);
                long c = cost(o);
                if (c < bc) {
                    bc = c;
                    bp = p;
                }
            }
            if (bc < best) {
                rest.insert(rest.begin() + static_cast<long>(bp), s);
                order = rest;
                best = bc;
                improved = true;
            }
        }
    }
    std::cerr << "link_order: greedy " << best << " B\n";
    // 2. Annealing: blocks of 1..4 sections moved, temperature 20 -> 0.5 bytes.
    std::mt19937 rng(20261121);
    std::uniform_real_distribution<double> uniform(0, 1);
    std::vector<int> cur = order;
    long cc = best;
    for (long it = 0; it < iterations; ++it) {
        double temp = 20.0 * std::pow(0.5 / 20.0, static_cast<double>(it) / iterations);
        size_t n = cur.size(), len = 1 + rng() % 4;
        if (len >= n) break;
        size_t from = rng() % (n - len + 1);
        std::vector<int> o = cur;
        std::vector<int> block(o.begin() + static_cast<long>(from),
                               o.begin() + static_cast<long>(from + len));
        o.erase(o.begin() + static_cast<long>(from), o.begin() + static_cast<long>(from + len));
        size_t to = rng() % (o.size() + 1);
        o.insert(o.begin() + static_cast<long>(to), block.begin(), block.end());
        long c = cost(o);
        if (c <= cc || uniform(rng) < std::exp(static_cast<double>(cc - c) / temp)) {
            cur = o;
            cc = c;
            if (cc < best) {
                best = cc;
                order = cur;
            }
        }
    }
    std::cerr << "link_order: annealed " << best << " B (" << start - best << " B less)\n";
    if (best >= 1000000L) {
        std::cerr << "link_order: a hand-written rcall/rjmp or a step vector cannot reach\n";
        return 1;
    }
    // The output: the header and the object-level lines of the current script (they place
    // whatever the list does not name, e.g. a new function), the list first.
    std::ifstream cur_in(argv[3]);
    std::string text((std::istreambuf_iterator<char>(cur_in)), std::istreambuf_iterator<char>());
    size_t header_end = text.find("*/");
    if (header_end == std::string::npos) {
        std::cerr << "link_order: " << argv[3] << " has no header comment\n";
        return 1;
    }
    std::string header = text.substr(0, header_end + 2);
    std::istringstream rest(text.substr(header_end + 2));
    std::ofstream out(argv[4]);
    out << header << "\n";
    for (int s : order) out << pattern(g_sec[static_cast<size_t>(s)]) << "\n";
    std::string line;
    while (std::getline(rest, line)) {
        if (line.find("(.text.*)") != std::string::npos) out << line << "\n";
    }
    return 0;
}
