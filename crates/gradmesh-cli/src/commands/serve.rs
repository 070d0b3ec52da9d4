//! `gradmesh serve`: the local web editor of `gradmesh-serve`.

use gradmesh::{Error, ErrorKind};

use crate::args::ServeArgs;

/// Serves the editor until the process is stopped.
pub fn run(args: &ServeArgs) -> Result<(), Error> {
    let config = gradmesh_serve::Config {
        file: args.files.first().cloned(),
        layers_above: args.files.iter().skip(1).cloned().collect(),
        folder: args.folder.clone(),
        port: args.port,
    };
    gradmesh_serve::run(&config).map_err(|message| Error::new(ErrorKind::Io(message)))
}
