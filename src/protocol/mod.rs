//! The Format B codec, sans-IO: bytes <-> typed commands and replies, in both roles.
