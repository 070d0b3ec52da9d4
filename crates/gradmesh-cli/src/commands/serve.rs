//! `gradmesh serve`: the local web editor of `gradmesh-serve`.

use gradmesh::{Error, ErrorKind};

use crate::args::ServeArgs;

/// Serves the editor until the process is stopped.
#[cfg(feature = "editor")]
pub fn run(args: &ServeArgs) -> Result<(), Error> {
    let config = gradmesh_serve::Config {
        file: args.files.first().cloned(),
        layers_above: args.files.iter().skip(1).cloned().collect(),
        folder: args.folder.clone(),
        port: args.port,
    };
    gradmesh_serve::run(&config).map_err(|message| Error::new(ErrorKind::Io(message)))
}

/// Without the editor's crate, says how to build it in.
#[cfg(not(feature = "editor"))]
pub fn run(_args: &ServeArgs) -> Result<(), Error> {
    Err(Error::new(ErrorKind::Invalid {
        what: "serve".into(),
        message: "this gradmesh was built without the editor (cargo feature `editor`, on by \
                  default): build it with `cargo build --release -p gradmesh-cli`"
            .into(),
    }))
}
