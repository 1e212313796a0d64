#pragma once
// Text into the pages and files the tools write (report.html, junit.xml, compare and sweep pages).
#include <string>

namespace stvl {

// For XML and HTML text and attribute values: & < > " escaped; control characters other than tab and line breaks
// (invalid in XML 1.0) become '?'.
inline std::string xml_escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n' && c != '\r') ? '?' : c;
    }
  }
  return out;
}

// For a script or JSON inlined in a <script> element: every "</" becomes "<\/", so nothing in it ends the element
// (the same string to JavaScript and to JSON).
inline std::string script_safe(std::string text) {
  for (std::size_t at = text.find("</"); at != std::string::npos; at = text.find("</", at + 3))
    text.replace(at, 2, "<\\/");
  return text;
}

}  // namespace stvl
