#pragma once
// The browser view server's rules for what it answers (web/stream_server.h),
// apart from the server so that the fuzz target (tests/fuzz/fuzz_web_request)
// applies them to websocketpp's parsing of arbitrary bytes.

#include <filesystem>
#include <string>

namespace sandbox::web {

// The file a GET of `resource` (a path, maybe with a query) serves: "/" the
// page's index.html, "/three/..." a file of three.js, any other path a file
// of the page. Empty for a path that leaves its folder or holds anything but
// letters, digits and . _ - / (the file may still not exist).
std::filesystem::path RequestedFile(const std::string& resource,
                                    const std::filesystem::path& page_dir,
                                    const std::filesystem::path& three_dir);

// Whether a Host header names this server as a browser reached it: an IP
// address, localhost or this machine's own name, with or without a port. A
// page on another name that resolves here (DNS rebinding) is refused.
bool HostAllowed(const std::string& host);

// Whether a WebSocket's Origin may connect: none (not a browser), or the
// page's own (http:// and the request's Host).
bool OriginAllowed(const std::string& origin, const std::string& host);

// The Content-Type a file is served as, by its extension.
std::string ContentType(const std::filesystem::path& file);

}  // namespace sandbox::web
