#pragma once
/// The token that calls changing the model must carry (Request.token): a random secret in a file
/// only the daemon's user may read. The daemon creates the file at start when it is missing; the
/// CLI reads it from the same place. Whoever can read the file may change the model; everyone on
/// the machine may read it (loopback).
#include <filesystem>
#include <string>
#include <string_view>

#include "scenewatch/core/result.h"

namespace scenewatch::service {

/// Where the daemon keeps its token unless server.token_file says otherwise, and where the CLI
/// looks for it unless --token-file does: $HOME/.scenewatch/token. Empty when HOME is not set.
std::filesystem::path default_token_path();

/// Reads the token at `path`, creating it first when it does not exist (64 hex digits from
/// getrandom, mode 0600, in a folder made with mode 0700 when missing). An existing file must be a
/// regular file (not a symlink) owned by this user that neither group nor others can read or
/// write, holding 16 to 4096 printable characters; otherwise the error names the file and the
/// problem.
Result<std::string> ensure_token_file(const std::filesystem::path& path);

/// Reads an existing token file with the checks of ensure_token_file() (the CLI's side).
Result<std::string> read_token_file(const std::filesystem::path& path);

/// True when both strings are equal. Takes the same time wherever they differ (the secret cannot
/// be guessed a byte at a time by timing replies); only the length of `expected` shows.
bool tokens_equal(std::string_view given, std::string_view expected);

}  // namespace scenewatch::service
