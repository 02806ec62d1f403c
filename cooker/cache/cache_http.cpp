// cache_http.cpp — the HTTP back end of the shared cook cache (see cache_store.h): Bazel's
// remote-cache protocol, GET and PUT of <url>/ac/<key> and <url>/cas/<key>, through libcurl.
//
// Each request is bounded in time (CURLOPT_TIMEOUT over the whole transfer, a shorter connect
// timeout) and in size (kMaxCacheEntryBytes), and runs without signals (CURLOPT_NOSIGNAL): the
// batch's workers each make their own requests, so a slow server delays one input by at most the
// timeout, and the batch stops asking once a lookup finds it unreachable (cook_cache.h). A handle
// is made per request (nothing of libcurl's is shared across fork()), and no request starts a
// thread (see resolve_once): the batch's own process looks entries up between forks.
#include <arpa/inet.h>
#include <curl/curl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <algorithm>

#include "cooker/cache/cache_store.h"

namespace ossa::cook {

namespace {

struct Download {
  std::vector<uint8_t> bytes;
  bool too_large = false;
};

size_t on_body(char* data, size_t size, size_t count, void* user) {
  auto* d = static_cast<Download*>(user);
  const size_t n = size * count;
  if (d->bytes.size() + n > kMaxCacheEntryBytes) {
    d->too_large = true;
    return 0;  // ends the transfer with CURLE_WRITE_ERROR
  }
  d->bytes.insert(d->bytes.end(), reinterpret_cast<uint8_t*>(data), reinterpret_cast<uint8_t*>(data) + n);
  return n;
}

struct Upload {
  std::span<const uint8_t> bytes;
  size_t at = 0;
};

size_t on_read(char* buffer, size_t size, size_t count, void* user) {
  auto* u = static_cast<Upload*>(user);
  const size_t n = std::min(size * count, u->bytes.size() - u->at);
  std::copy_n(u->bytes.data() + u->at, n, reinterpret_cast<uint8_t*>(buffer));
  u->at += n;
  return n;
}

/// Failures that say the server is not there to ask (or does not speak HTTP): the batch stops.
bool unreachable(CURLcode code) {
  switch (code) {
    case CURLE_COULDNT_CONNECT:
    case CURLE_COULDNT_RESOLVE_HOST:
    case CURLE_COULDNT_RESOLVE_PROXY:
    case CURLE_OPERATION_TIMEDOUT:
    case CURLE_GOT_NOTHING:
    case CURLE_RECV_ERROR:
    case CURLE_SEND_ERROR:
    case CURLE_WEIRD_SERVER_REPLY:
    case CURLE_SSL_CONNECT_ERROR: return true;
    default: return false;
  }
}

class HttpStore final : public CacheStore {
 public:
  HttpStore(std::string url, unsigned timeout_seconds) : url_(std::move(url)), timeout_(std::max(1u, timeout_seconds)) {
    while (!url_.empty() && url_.back() == '/') url_.pop_back();
    resolve_once();
  }
  ~HttpStore() override { curl_slist_free_all(resolved_); }
  HttpStore(const HttpStore&) = delete;
  HttpStore& operator=(const HttpStore&) = delete;

  CacheGet get(std::string_view kind, std::string_view key) override {
    CacheGet result;
    if (!resolve_error_.empty()) {
      result.trouble = CacheTrouble{url_ + ": " + resolve_error_, true};
      return result;
    }
    Download download;
    CURL* curl = handle(kind, key);
    if (curl == nullptr) {
      result.trouble = CacheTrouble{url_ + ": cannot make an HTTP request", false};
      return result;
    }
    curl_easy_setopt(curl, CURLOPT_WRITEFUNCTION, on_body);
    curl_easy_setopt(curl, CURLOPT_WRITEDATA, &download);
    const CURLcode code = curl_easy_perform(curl);
    long status = 0;
    curl_easy_getinfo(curl, CURLINFO_RESPONSE_CODE, &status);
    curl_easy_cleanup(curl);
    if (code != CURLE_OK) {
      result.trouble = trouble(kind, key, download.too_large ? "an answer over 4 GiB" : curl_easy_strerror(code),
                               !download.too_large && unreachable(code));
    } else if (status == 200) {
      result.bytes = std::move(download.bytes);
    } else if (status != 404) {
      result.trouble = trouble(kind, key, "HTTP status " + std::to_string(status), false);
    }
    return result;
  }

  std::optional<CacheTrouble> put(std::string_view kind, std::string_view key,
                                  std::span<const uint8_t> bytes) override {
    if (!resolve_error_.empty()) return CacheTrouble{url_ + ": " + resolve_error_, true};
    Upload upload{bytes, 0};
    Download answer;  // the server's words, kept small and unused
    CURL* curl = handle(kind, key);
    if (curl == nullptr) return CacheTrouble{url_ + ": cannot make an HTTP request", false};
    curl_easy_setopt(curl, CURLOPT_UPLOAD, 1L);
    curl_easy_setopt(curl, CURLOPT_READFUNCTION, on_read);
    curl_easy_setopt(curl, CURLOPT_READDATA, &upload);
    curl_easy_setopt(curl, CURLOPT_INFILESIZE_LARGE, static_cast<curl_off_t>(bytes.size()));
    curl_easy_setopt(curl, CURLOPT_WRITEFUNCTION, on_body);
    curl_easy_setopt(curl, CURLOPT_WRITEDATA, &answer);
    curl_slist* headers = curl_slist_append(nullptr, "Expect:");  // no 100-continue round trip
    headers = curl_slist_append(headers, "Content-Type: application/octet-stream");
    curl_easy_setopt(curl, CURLOPT_HTTPHEADER, headers);
    const CURLcode code = curl_easy_perform(curl);
    long status = 0;
    curl_easy_getinfo(curl, CURLINFO_RESPONSE_CODE, &status);
    curl_easy_cleanup(curl);
    curl_slist_free_all(headers);
    if (code != CURLE_OK)
      return trouble(kind, key, std::string("storing: ") + curl_easy_strerror(code), unreachable(code));
    if (status != 200 && status != 201 && status != 204)
      return trouble(kind, key, "storing: HTTP status " + std::to_string(status), false);
    return std::nullopt;
  }

  std::string name() const override { return url_; }

 private:
  CURL* handle(std::string_view kind, std::string_view key) const {
    CURL* curl = curl_easy_init();
    if (curl == nullptr) return nullptr;
    const std::string url = url_ + "/" + std::string(kind) + "/" + std::string(key);
    curl_easy_setopt(curl, CURLOPT_URL, url.c_str());
    curl_easy_setopt(curl, CURLOPT_NOSIGNAL, 1L);
    curl_easy_setopt(curl, CURLOPT_TIMEOUT, static_cast<long>(timeout_));
    curl_easy_setopt(curl, CURLOPT_CONNECTTIMEOUT, static_cast<long>(std::min(timeout_, 3u)));
    curl_easy_setopt(curl, CURLOPT_FOLLOWLOCATION, 0L);
    curl_easy_setopt(curl, CURLOPT_PROTOCOLS_STR, "http,https");
    curl_easy_setopt(curl, CURLOPT_USERAGENT, "ossa-cook");
    if (resolved_ != nullptr) curl_easy_setopt(curl, CURLOPT_RESOLVE, resolved_);
    return curl;
  }

  /// The server's name resolved here, once, with the blocking getaddrinfo, and handed to every
  /// request (CURLOPT_RESOLVE): libcurl's own resolver runs in a thread, and the batch's process,
  /// which looks entries up, must stay single-threaded because it forks its workers (worker.h).
  void resolve_once() {
    CURLU* u = curl_url();
    char* host = nullptr;
    char* port = nullptr;
    if (u == nullptr || curl_url_set(u, CURLUPART_URL, url_.c_str(), 0) != CURLUE_OK ||
        curl_url_get(u, CURLUPART_HOST, &host, 0) != CURLUE_OK ||
        curl_url_get(u, CURLUPART_PORT, &port, CURLU_DEFAULT_PORT) != CURLUE_OK) {
      resolve_error_ = "not a URL libcurl reads";
    } else {
      std::string name = host;
      if (name.size() > 2 && name.front() == '[') name = name.substr(1, name.size() - 2);  // [::1]
      addrinfo hints{};
      hints.ai_socktype = SOCK_STREAM;
      addrinfo* found = nullptr;
      if (const int rc = ::getaddrinfo(name.c_str(), port, &hints, &found); rc != 0) {
        resolve_error_ = "cannot resolve '" + name + "': " + ::gai_strerror(rc);
      } else {
        std::string addresses;
        for (const addrinfo* a = found; a != nullptr; a = a->ai_next) {
          char text[INET6_ADDRSTRLEN] = {};
          const void* where =
              a->ai_family == AF_INET6
                  ? static_cast<const void*>(&reinterpret_cast<const sockaddr_in6*>(a->ai_addr)->sin6_addr)
                  : static_cast<const void*>(&reinterpret_cast<const sockaddr_in*>(a->ai_addr)->sin_addr);
          if (::inet_ntop(a->ai_family, where, text, sizeof text) == nullptr) continue;
          const std::string one = a->ai_family == AF_INET6 ? "[" + std::string(text) + "]" : std::string(text);
          if (addresses.find(one) == std::string::npos) addresses += (addresses.empty() ? "" : ",") + one;
        }
        ::freeaddrinfo(found);
        if (!addresses.empty())
          resolved_ = curl_slist_append(nullptr, (std::string(host) + ":" + port + ":" + addresses).c_str());
      }
    }
    curl_free(host);
    curl_free(port);
    curl_url_cleanup(u);
  }
  CacheTrouble trouble(std::string_view kind, std::string_view key, const std::string& why, bool down) const {
    return CacheTrouble{url_ + ": " + std::string(kind) + "/" + std::string(key) + ": " + why, down};
  }

  std::string url_;
  unsigned timeout_;
  curl_slist* resolved_ = nullptr;  // "host:port:address[,address...]"
  std::string resolve_error_;       // set when the name does not resolve: every request is trouble
};

}  // namespace

bool http_cache_available() { return true; }

Result<std::unique_ptr<CacheStore>> http_cache_store(const std::string& url, unsigned timeout_seconds) {
  // Once, in the batch's single thread, before any worker is forked (curl_global_init is not
  // thread-safe); the workers inherit it.
  static const CURLcode init = curl_global_init(CURL_GLOBAL_DEFAULT);
  if (init != CURLE_OK) return Error{"--cache " + url + ": libcurl: " + curl_easy_strerror(init)};
  return std::unique_ptr<CacheStore>(std::make_unique<HttpStore>(url, timeout_seconds));
}

}  // namespace ossa::cook
