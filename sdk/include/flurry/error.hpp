// Flurry's exceptions. Every error the SDK raises derives from flurry::Error, itself a
// std::runtime_error, and carries what a caller can act on (the parameter, the path).
#pragma once

#include <stdexcept>
#include <string>

namespace flurry {

/// Root of every exception Flurry throws.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A parameter was out of range, not finite, or described a degenerate shape.
/// parameter() names it ("rate", "Sphere.radius", "emitters[2].rate").
class InvalidArgument : public Error {
 public:
  InvalidArgument(std::string parameter, const std::string& why)
      : Error(parameter + ": " + why), parameter_(std::move(parameter)) {}
  const std::string& parameter() const noexcept { return parameter_; }

 private:
  std::string parameter_;
};

/// A file could not be read or written. path() names it.
class IoError : public Error {
 public:
  IoError(std::string path, const std::string& why)
      : Error(path + ": " + why), path_(std::move(path)) {}
  const std::string& path() const noexcept { return path_; }

 private:
  std::string path_;
};

}  // namespace flurry
