//! The `lapidary` binary; everything lives in the library's [`lapidary::cli`].

fn main() -> std::process::ExitCode {
    lapidary::cli::run()
}
