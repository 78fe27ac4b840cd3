#pragma once
// Shared by fuzz_solid_request and fuzz_fluid_request.
//
// Input format: a sequence of chunks  [length: 2 bytes, little endian][length bytes]; each
// chunk is one serialised fsi.v1.Request, sent in order to ONE fresh service (as a coupler
// would: hello -> configure -> get_interface -> solve_step ... -> accept_step -> save/load
// checkpoint -> stop). A truncated last chunk is sent as it is; at most kMaxRequests.
//
// Before a request reaches the service the harness:
//  - clears Configure.output_dir (the fuzzer must not write files anywhere),
//  - skips (does not send) a Configure whose scene would be slow or touch files/processes
//    (the target decides: `admit_configure`), so one input stays well under ~10 ms.
// Oracle: handle_bytes never throws; the reply parses as fsi.v1.Reply, echoes the version
// and the sequence; an Error reply INTERNAL (an unexpected exception type inside a model)
// is a finding unless FSI_FUZZ_ALLOW_INTERNAL is set. Stop ends the sequence.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "fsi/common/config.hpp"
#include "fsi/protocol/client.hpp"
#include "fsi/protocol/service.hpp"

namespace fsi_fuzz {

constexpr std::size_t kMaxRequests = 24;

inline std::vector<std::string> split_requests(const uint8_t* data, size_t size) {
  std::vector<std::string> out;
  size_t at = 0;
  while (at < size && out.size() < kMaxRequests) {
    if (size - at < 2) {
      out.emplace_back(reinterpret_cast<const char*>(data + at), size - at);
      break;
    }
    const size_t n = static_cast<size_t>(data[at]) | (static_cast<size_t>(data[at + 1]) << 8);
    at += 2;
    const size_t take = n < size - at ? n : size - at;
    out.emplace_back(reinterpret_cast<const char*>(data + at), take);
    at += take;
  }
  return out;
}

inline std::string join_requests(const std::vector<std::string>& requests) {
  std::string out;
  for (const auto& r : requests) {
    if (r.size() > 0xffff) std::abort();
    out.push_back(static_cast<char>(r.size() & 0xff));
    out.push_back(static_cast<char>(r.size() >> 8));
    out += r;
  }
  return out;
}

// The value of `key` in a YAML map, looked up the way fsi::ConfigSection does (first key
// whose scalar text equals `key`); an undefined node if absent.
inline YAML::Node lookup(const YAML::Node& map, const std::string& key) {
  if (map.IsMap())
    for (const auto& kv : map)
      if (kv.first.Scalar() == key) return kv.second;
  return YAML::Node(YAML::NodeType::Undefined);
}

inline std::string scalar(const YAML::Node& node) { return node && node.IsScalar() ? node.Scalar() : std::string(); }

// Parses the Configure's scene as the service will (same text, overrides) and returns the
// section it will configure from, or an undefined node when the scene does not parse (the
// service will then refuse it itself: safe to send).
inline YAML::Node configured_section(const fsi::v1::Configure& c, const char* default_section) {
  try {
    std::vector<std::string> overrides(c.overrides().begin(), c.overrides().end());
    const fsi::Scene scene = fsi::Scene::parse(c.scene_text(), "<fuzz>", overrides);
    return lookup(scene.root_node(), c.section().empty() ? default_section : c.section());
  } catch (...) {
    return YAML::Node(YAML::NodeType::Undefined);
  }
}

// Size of a YAML list (0 if absent or not a list).
inline std::size_t list_size(const YAML::Node& node) { return node && node.IsSequence() ? node.size() : 0; }

// An int the way ConfigSection::get<int> reads it, or `fallback` if it would not convert.
inline long long as_int(const YAML::Node& node, long long fallback) {
  try {
    if (node && node.IsScalar()) return node.as<int>();
  } catch (...) {
  }
  return fallback;
}

template <class Service, class Admit>
int run_requests(Service& service, const uint8_t* data, size_t size, Admit admit_configure) {
  static const bool allow_internal = std::getenv("FSI_FUZZ_ALLOW_INTERNAL") != nullptr;
  for (std::string bytes : split_requests(data, size)) {
    fsi::v1::Request request;
    if (request.ParseFromString(bytes) && request.has_configure()) {
      if (request.configure().scene_text().size() > 8192 || request.configure().overrides_size() > 16) continue;
      if (!admit_configure(request.configure())) continue;
      if (!request.configure().output_dir().empty()) {
        request.mutable_configure()->clear_output_dir();
        bytes = request.SerializeAsString();
      }
    }
    bool stop = false;
    const std::string reply_bytes = service.handle_bytes(bytes, stop);  // must not throw
    fsi::v1::Reply reply;
    if (!reply.ParseFromString(reply_bytes)) {
      std::fprintf(stderr, "fuzz: the reply does not parse as fsi.v1.Reply\n");
      std::abort();
    }
    if (reply.protocol_version() != fsi::protocol::kProtocolVersion) {
      std::fprintf(stderr, "fuzz: the reply has protocol version %u\n", reply.protocol_version());
      std::abort();
    }
    if (reply.has_error() && reply.error().code() == fsi::v1::Error::INTERNAL && !allow_internal) {
      std::fprintf(stderr, "fuzz: INTERNAL error reply (an unexpected exception type): %s\n",
                   reply.error().message().c_str());
      std::abort();
    }
    if (reply.body_case() == fsi::v1::Reply::BODY_NOT_SET) {
      std::fprintf(stderr, "fuzz: a reply without a body\n");
      std::abort();
    }
    if (stop) break;
  }
  return 0;
}

inline void quiet_logs() { setenv("FSI_LOG_LEVEL", "off", 1); }

}  // namespace fsi_fuzz
