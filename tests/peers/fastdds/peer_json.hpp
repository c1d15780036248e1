// A small JSON reader and writer for the Fast DDS peer's command protocol (one JSON object per
// line on stdin, one per line on stdout). Debian has no header-only C++ JSON library installed by
// default, and the peer's needs are small: objects, arrays, strings, numbers, booleans, null.
// Numbers are doubles (the string "NaN" is read as a NaN where a number is expected, as the
// Python peers accept it).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace pj {

struct Value {
    enum Kind { Null, Bool, Number, String, Array, Object } kind = Null;
    bool b = false;
    double n = 0.0;
    std::string s;
    std::vector<Value> a;
    std::map<std::string, Value> o;

    bool has(const std::string& key) const { return kind == Object && o.count(key) > 0; }
    const Value& operator[](const std::string& key) const {
        static const Value null;
        if (kind != Object) return null;
        auto it = o.find(key);
        return it == o.end() ? null : it->second;
    }
    double num(double fallback = 0.0) const {
        if (kind == Number) return n;
        if (kind == String && (s == "NaN" || s == "nan")) return std::nan("");
        return fallback;
    }
    int64_t i64(int64_t fallback = 0) const { return kind == Number ? static_cast<int64_t>(n) : fallback; }
    std::string str(const std::string& fallback = "") const { return kind == String ? s : fallback; }
    bool boolean(bool fallback = false) const { return kind == Bool ? b : fallback; }
    const std::vector<Value>& arr() const {
        static const std::vector<Value> empty;
        return kind == Array ? a : empty;
    }
    std::vector<double> nums() const {
        std::vector<double> v;
        for (const auto& x : arr()) v.push_back(x.num());
        return v;
    }
    std::vector<std::string> strs() const {
        std::vector<std::string> v;
        for (const auto& x : arr()) v.push_back(x.str());
        return v;
    }
};

class Parser {
public:
    explicit Parser(const std::string& text) : t_(text) {}
    Value parse() {
        Value v = value();
        ws();
        if (i_ != t_.size()) fail("trailing characters");
        return v;
    }

private:
    const std::string& t_;
    size_t i_ = 0;

    [[noreturn]] void fail(const char* what) { throw std::runtime_error(std::string("JSON: ") + what + " at " + std::to_string(i_)); }
    void ws() {
        while (i_ < t_.size() && (t_[i_] == ' ' || t_[i_] == '\t' || t_[i_] == '\n' || t_[i_] == '\r')) ++i_;
    }
    bool eat(const char* word) {
        size_t n = std::char_traits<char>::length(word);
        if (t_.compare(i_, n, word) == 0) {
            i_ += n;
            return true;
        }
        return false;
    }
    Value value() {
        ws();
        if (i_ >= t_.size()) fail("unexpected end");
        Value v;
        char c = t_[i_];
        if (c == '{') {
            v.kind = Value::Object;
            ++i_;
            ws();
            if (i_ < t_.size() && t_[i_] == '}') { ++i_; return v; }
            for (;;) {
                ws();
                if (i_ >= t_.size() || t_[i_] != '"') fail("expected a key");
                std::string key = string();
                ws();
                if (i_ >= t_.size() || t_[i_] != ':') fail("expected ':'");
                ++i_;
                v.o[key] = value();
                ws();
                if (i_ < t_.size() && t_[i_] == ',') { ++i_; continue; }
                if (i_ < t_.size() && t_[i_] == '}') { ++i_; return v; }
                fail("expected ',' or '}'");
            }
        }
        if (c == '[') {
            v.kind = Value::Array;
            ++i_;
            ws();
            if (i_ < t_.size() && t_[i_] == ']') { ++i_; return v; }
            for (;;) {
                v.a.push_back(value());
                ws();
                if (i_ < t_.size() && t_[i_] == ',') { ++i_; continue; }
                if (i_ < t_.size() && t_[i_] == ']') { ++i_; return v; }
                fail("expected ',' or ']'");
            }
        }
        if (c == '"') {
            v.kind = Value::String;
            v.s = string();
            return v;
        }
        if (eat("true")) { v.kind = Value::Bool; v.b = true; return v; }
        if (eat("false")) { v.kind = Value::Bool; return v; }
        if (eat("null")) return v;
        if (eat("NaN")) { v.kind = Value::Number; v.n = std::nan(""); return v; }
        size_t start = i_;
        while (i_ < t_.size() && std::string("+-0123456789.eE").find(t_[i_]) != std::string::npos) ++i_;
        if (start == i_) fail("unexpected character");
        v.kind = Value::Number;
        v.n = std::stod(t_.substr(start, i_ - start));
        return v;
    }
    std::string string() {
        ++i_;  // the opening quote
        std::string out;
        while (i_ < t_.size() && t_[i_] != '"') {
            char c = t_[i_++];
            if (c != '\\') { out += c; continue; }
            if (i_ >= t_.size()) fail("bad escape");
            char e = t_[i_++];
            switch (e) {
                case 'n': out += '\n'; break;
                case 't': out += '\t'; break;
                case 'r': out += '\r'; break;
                case 'b': out += '\b'; break;
                case 'f': out += '\f'; break;
                case 'u': {
                    if (i_ + 4 > t_.size()) fail("bad \\u escape");
                    unsigned cp = std::stoul(t_.substr(i_, 4), nullptr, 16);
                    i_ += 4;
                    // Surrogate pairs are not needed by the tests; BMP code points as UTF-8.
                    if (cp < 0x80) out += static_cast<char>(cp);
                    else if (cp < 0x800) { out += static_cast<char>(0xC0 | (cp >> 6)); out += static_cast<char>(0x80 | (cp & 0x3F)); }
                    else { out += static_cast<char>(0xE0 | (cp >> 12)); out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F)); out += static_cast<char>(0x80 | (cp & 0x3F)); }
                    break;
                }
                default: out += e;
            }
        }
        if (i_ >= t_.size()) fail("unterminated string");
        ++i_;
        return out;
    }
};

inline Value parse(const std::string& text) { return Parser(text).parse(); }

// Writing: JSON text built from small pieces.
inline std::string quote(const std::string& s) {
    std::string out = "\"";
    for (unsigned char c : s) {
        switch (c) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\r': out += "\\r"; break;
            case '\t': out += "\\t"; break;
            default:
                if (c < 0x20) {
                    char buf[8];
                    std::snprintf(buf, sizeof buf, "\\u%04x", c);
                    out += buf;
                } else {
                    out += static_cast<char>(c);
                }
        }
    }
    return out + "\"";
}

inline std::string number(double x) {
    if (std::isnan(x)) return "\"NaN\"";
    if (std::isinf(x)) return x > 0 ? "\"inf\"" : "\"-inf\"";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", x);
    return buf;
}

inline std::string integer(int64_t x) { return std::to_string(x); }
inline std::string boolean(bool x) { return x ? "true" : "false"; }

// An object written key by key: Obj().add("a", number(1)).str().
class Obj {
public:
    Obj& add(const std::string& key, const std::string& json) {
        if (!first_) s_ += ",";
        first_ = false;
        s_ += quote(key) + ":" + json;
        return *this;
    }
    std::string str() const { return "{" + s_ + "}"; }

private:
    std::string s_;
    bool first_ = true;
};

template <class T, class F>
std::string array(const std::vector<T>& xs, F each) {
    std::string out = "[";
    for (size_t k = 0; k < xs.size(); ++k) {
        if (k) out += ",";
        out += each(xs[k]);
    }
    return out + "]";
}

inline std::string nums(const std::vector<double>& xs) { return array(xs, [](double x) { return number(x); }); }
inline std::string strs(const std::vector<std::string>& xs) { return array(xs, [](const std::string& x) { return quote(x); }); }

}  // namespace pj
