// Where memory landed: how many bytes of this process's anonymous memory sit
// in transparent huge pages, and which THP mode the kernel is in. The run's
// memory policy (BackendConfig::huge_pages) only asks for huge pages; these
// say what the kernel gave, per build (the progress line) and per run (the
// metadata's `thp`).
// Source: Linux's /proc/self/smaps_rollup (field AnonHugePages, in kB) and
// /sys/kernel/mm/transparent_hugepage/enabled ("always [madvise] never").
// Guarantee: never throws; off Linux, or where the files are missing or
// malformed, the answers say "unavailable" (std::nullopt) rather than 0.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace raybench {

// Bytes of AnonHugePages in a smaps_rollup (or smaps) text: the sum of
// every "AnonHugePages: N kB" line times 1024; nullopt without such a line
// or with a malformed one.
std::optional<std::size_t> parse_anon_huge_page_bytes(std::string_view smaps_text);

// Bytes of this process's anonymous memory in huge pages now (from
// /proc/self/smaps_rollup); nullopt where it cannot be read.
std::optional<std::size_t> anon_huge_page_bytes();

// The bracketed word of a transparent_hugepage/enabled text ("always
// [madvise] never" -> "madvise"); "" when there is none.
std::string parse_thp_mode(std::string_view enabled_text);

// The kernel's THP mode ("always", "madvise", "never"), or "unavailable"
// where /sys/kernel/mm/transparent_hugepage/enabled cannot be read.
std::string transparent_huge_pages_mode();

}  // namespace raybench
