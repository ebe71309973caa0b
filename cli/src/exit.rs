//! How a command ends: its error printed, and an exit code that tells a
//! script whether to retry.

use std::process::ExitCode;

/// Errors end the program with a message and a non-zero exit code, never a panic.
pub type CliResult = Result<(), Box<dyn std::error::Error>>;

/// The exit code of a command's result, its error printed to stderr.
pub fn code(result: CliResult) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of our output has gone; it asked for no more.
        Err(e) if is_broken_pipe(e.as_ref()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", shortened(&e.to_string()));
            ExitCode::from(error_code(e.as_ref()))
        }
    }
}

/// Exit codes (README): 0 done; 1 the system failed us (a read or write
/// the operating system refused: permissions, a full disk; too little
/// memory for the work); 2 the command
/// line or an input is wrong (a missing input is [`sfp_core::Error::read`]'s
/// `File`; clap's own usage errors also exit with 2). Scripts and job
/// schedulers can retry the first and must not retry the second.
fn error_code(e: &(dyn std::error::Error + 'static)) -> u8 {
    match e.downcast_ref::<sfp_core::Error>() {
        Some(sfp_core::Error::Io { .. } | sfp_core::Error::Memory(_)) => 1,
        Some(_) => 2,
        None if e.is::<std::io::Error>() => 1,
        None => 2,
    }
}

/// Longest line of an error printed whole: a message quoting a huge input
/// (a 15 MB key in a TOML file, echoed with its caret line) keeps the head
/// of each long line and says how much was left out.
const MAX_LINE: usize = 400;

fn shortened(message: &str) -> String {
    message
        .lines()
        .map(|line| match line.char_indices().nth(MAX_LINE) {
            Some((cut, _)) => format!(
                "{}… ({} more characters)",
                &line[..cut],
                line[cut..].chars().count()
            ),
            None => line.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn is_broken_pipe(e: &(dyn std::error::Error + 'static)) -> bool {
    e.downcast_ref::<std::io::Error>()
        .is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe)
}
