#include "vibid/common/json_file.hpp"

#include "vibid/common/atomic_file.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/text_input.hpp"

namespace vibid {

nlohmann::json ReadJsonFile(const std::string& path) {
  return ParseJsonText(ReadFileText(path, kMaxJsonFileBytes), path);
}

nlohmann::json ParseJsonText(std::string_view text, const std::string& source) {
  RequireUtf8(text, source);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // Turn the byte offset into a line number: that is what an editor shows.
    std::size_t line = 1;
    for (std::size_t i = 0; i < e.byte && i < text.size(); ++i) line += text[i] == '\n';
    if (text.find_first_not_of(" \t\r\n") == std::string::npos)
      throw InputError(source + ": empty file (no JSON)");
    // The parser's offset points one past the end when the text stops inside a value.
    if (e.byte > text.size())
      throw InputError(source + ":" + std::to_string(line) +
                       ": malformed JSON (the file ends inside a value: truncated?)");
    throw InputError(source + ":" + std::to_string(line) + ": malformed JSON");
  } catch (const nlohmann::json::out_of_range&) {
    // The parser throws this (not a parse_error) for a number beyond double's range, e.g. 1e999.
    throw InputError(source + ": malformed JSON: a number is out of range");
  }
}

void WriteJsonFile(const std::string& path, const nlohmann::json& value) {
  WriteFileAtomic(path, value.dump(2) + "\n");
}

}  // namespace vibid
