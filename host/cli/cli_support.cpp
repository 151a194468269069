#include "cli_support.hpp"

#include <iostream>

#include "vibid/common/option_text.hpp"
#include "vibid/common/atomic_file.hpp"

namespace vibid::cli {

void EmitOutput(const std::string& content, const std::string& path) {
  if (path.empty() || path == "-") {
    std::cout << content;
    std::cout.flush();
  } else {
    WriteFileAtomic(path, content);
  }
}

ClaimedOutput::ClaimedOutput(const std::string& path) {
  if (!path.empty() && path != "-") file_ = std::make_unique<AtomicOutputFile>(path);
}

void ClaimedOutput::Write(std::string_view content) {
  if (file_) {
    file_->Commit(content);
  } else {
    std::cout << content;
    std::cout.flush();
  }
}

std::string ClaimedOutput::Name() const { return file_ ? file_->path() : "stdout"; }

namespace {

CLI::Validator NumberValidator(bool allow_zero) {
  return CLI::Validator(
      [allow_zero](std::string& s) -> std::string {
        double v = 0.0;
        switch (ParseNumber(s, v)) {
          case NumberText::kNotANumber: return "'" + s + "' is not a number";
          case NumberText::kNotFinite: return "'" + s + "' is not a finite number";
          case NumberText::kOk: break;
        }
        if (allow_zero ? v < 0.0 : v <= 0.0)
          return "'" + s + (allow_zero ? "' must be >= 0" : "' must be > 0");
        return {};
      },
      allow_zero ? "NUMBER>=0" : "NUMBER>0");
}

}  // namespace

const CLI::Validator& PositiveNumber() {
  static const CLI::Validator v = NumberValidator(false);
  return v;
}

const CLI::Validator& NonNegativeNumber() {
  static const CLI::Validator v = NumberValidator(true);
  return v;
}

}  // namespace vibid::cli
