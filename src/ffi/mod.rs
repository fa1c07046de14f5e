//! The C ABI: the only place with `extern "C"`.
