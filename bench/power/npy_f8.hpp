// The benchmark drivers' reader of the inputs gen_power.py writes.
#pragma once

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace power_bench {

// A C-order little-endian float64 .npy array: its values and its shape.
inline std::vector<double> read_f8(const std::string& path, std::vector<std::size_t>& shape) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("cannot open " + path);
  char magic[8];
  f.read(magic, 8);
  std::uint16_t hlen = 0;
  f.read(reinterpret_cast<char*>(&hlen), 2);  // version 1 header
  std::string header(hlen, ' ');
  f.read(header.data(), hlen);
  if (header.find("'<f8'") == std::string::npos || header.find("'fortran_order': False") == std::string::npos)
    throw std::runtime_error(path + ": expected a C-order float64 array");
  const auto open = header.find('('), close = header.find(')');
  shape.clear();
  std::size_t total = 1, at = open + 1;
  while (at < close) {
    const std::size_t comma = std::min(header.find(',', at), close);
    const std::string part = header.substr(at, comma - at);
    if (part.find_first_of("0123456789") != std::string::npos) {
      shape.push_back(std::stoull(part));
      total *= shape.back();
    }
    at = comma + 1;
  }
  std::vector<double> v(total);
  f.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(total * sizeof(double)));
  if (!f) throw std::runtime_error(path + ": truncated");
  return v;
}

}  // namespace power_bench
