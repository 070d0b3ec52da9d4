//! Standard output that a closed reader ends quietly: `gradmesh info big.svg | head` stops
//! when `head` has read its lines, with exit status 0, instead of panicking as `println!`
//! does on a broken pipe.

use std::fmt::Arguments;
use std::io::{ErrorKind, Write};

/// Writes `args` to standard output. A reader that went away ends the process with status 0;
/// any other failure to write ends it with a message and status 1.
pub fn write(args: Arguments<'_>) {
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|()| out.flush()) {
        if e.kind() == ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("gradmesh: error: could not write to standard output: {e}");
        std::process::exit(1);
    }
}

/// `print!` through [`write`].
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::output::write(format_args!($($arg)*))
    };
}

/// `println!` through [`write`].
macro_rules! outln {
    () => {
        $crate::output::write(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::output::write(format_args!("{}\n", format_args!($($arg)*)))
    };
}

pub(crate) use {out, outln};
