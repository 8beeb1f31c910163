// The one exception type for bad input: it carries the file and line so main can print one line.
// Text from the input that goes into a message passes through quote() (capped), and every line pt
// prints passes through printable() (escaped), so a message stays one short line and no escape
// sequence from a file reaches the terminal.
#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace pt {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
  Error(const std::string& file, const std::string& message)
      : std::runtime_error(file + ": " + message) {}
  Error(const std::string& file, int line, const std::string& message)
      : std::runtime_error(file + ":" + std::to_string(line) + ": " + message) {}
};

constexpr size_t kMaxQuotedBytes = 64;     // of one token quoted in a message
constexpr size_t kMaxMessageBytes = 4096;  // of one printed line

// `text` with control characters (C0, DEL and the C1 range), invalid UTF-8 and backslashes escaped
// as \n, \t, \r, \\ or \xNN, cut after `max_bytes` of input with "... (N bytes)".
inline std::string printable(std::string_view text, size_t max_bytes = kMaxMessageBytes) {
  static const char* kHex = "0123456789abcdef";
  std::string out;
  size_t i = 0;
  auto escape = [&](unsigned char c) {
    out += "\\x";
    out += kHex[c >> 4];
    out += kHex[c & 15];
  };
  while (i < text.size() && i < max_bytes) {
    unsigned char c = static_cast<unsigned char>(text[i]);
    if (c < 0x80) {
      if (c == '\n') out += "\\n";
      else if (c == '\t') out += "\\t";
      else if (c == '\r') out += "\\r";
      else if (c == '\\') out += "\\\\";
      else if (c < 0x20 || c == 0x7f) escape(c);
      else out += static_cast<char>(c);
      ++i;
      continue;
    }
    // A UTF-8 sequence passes whole if it is well formed, shortest-form and not a C1 control.
    size_t n = c >= 0xf0 ? (c <= 0xf4 ? 4 : 0) : c >= 0xe0 ? 3 : c >= 0xc2 ? 2 : 0;
    bool ok = n > 0 && i + n <= text.size();
    uint32_t cp = n == 4 ? c & 0x07 : n == 3 ? c & 0x0f : c & 0x1f;
    for (size_t k = 1; ok && k < n; ++k) {
      unsigned char d = static_cast<unsigned char>(text[i + k]);
      ok = (d & 0xc0) == 0x80;
      cp = (cp << 6) | (d & 0x3f);
    }
    ok = ok && !(n == 3 && cp < 0x800) && !(n == 4 && (cp < 0x10000 || cp > 0x10ffff)) && !(cp >= 0xd800 && cp <= 0xdfff) &&
         !(cp >= 0x80 && cp <= 0x9f);
    if (ok) {
      out.append(text.substr(i, n));
      i += n;
    } else {
      escape(c);
      ++i;
    }
  }
  if (i < text.size()) out += "... (" + std::to_string(text.size()) + " bytes)";
  return out;
}

// A token from the input cut after kMaxQuotedBytes ("... (N bytes)" says how long it was), and the
// same single-quoted for a message. Escaping is left to printable(), which main applies once to
// every line it prints.
inline std::string cut(std::string_view token) {
  if (token.size() <= kMaxQuotedBytes) return std::string(token);
  return std::string(token.substr(0, kMaxQuotedBytes)) + "... (" + std::to_string(token.size()) + " bytes)";
}
inline std::string quote(std::string_view token) {
  std::string out(1, '\'');  // appended, not "'" + ...: GCC 12 warns falsely (-Wrestrict) on that
  out += cut(token);
  out += '\'';
  return out;
}

}  // namespace pt
