//! A small HTTP/1.1 file server on the loopback address for the OME-Zarr tests: GET and
//! HEAD of the files under a folder (every response closes its connection), with faults
//! injected per path: a status code instead of the file, or the connection dropped
//! without an answer. It counts the requests it gets.

use std::collections::HashMap;
use std::io::{BufRead, BufReader, Write};
use std::net::{TcpListener, TcpStream};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// What the server does instead of serving a path.
#[derive(Clone, Copy, Debug)]
pub enum Fault {
    Status(u16),
    Drop,
}

pub struct Server {
    /// `http://127.0.0.1:PORT`.
    pub url: String,
    faults: Arc<Mutex<HashMap<String, Fault>>>,
    requests: Arc<AtomicUsize>,
}

impl Server {
    /// Serves `root` from a thread until the test process ends.
    pub fn start(root: PathBuf) -> Server {
        let listener = TcpListener::bind("127.0.0.1:0").expect("a loopback port");
        let url = format!("http://{}", listener.local_addr().expect("address"));
        let faults: Arc<Mutex<HashMap<String, Fault>>> = Arc::default();
        let requests: Arc<AtomicUsize> = Arc::default();
        let (shared, counted) = (faults.clone(), requests.clone());
        std::thread::spawn(move || {
            for stream in listener.incoming().flatten() {
                counted.fetch_add(1, Ordering::SeqCst);
                let (root, faults) = (root.clone(), shared.clone());
                std::thread::spawn(move || answer(stream, &root, &faults));
            }
        });
        Server { url, faults, requests }
    }

    /// From now on `path` is served again.
    pub fn heal(&self, path: &str) {
        self.faults.lock().unwrap_or_else(|p| p.into_inner()).remove(&format!("/{path}"));
    }

    /// Requests (connections: every response closes its own) so far.
    pub fn requests(&self) -> usize {
        self.requests.load(Ordering::SeqCst)
    }

    /// From now on `path` (from the root, `a/b/c`) answers with `fault`.
    pub fn inject(&self, path: &str, fault: Fault) {
        self.faults.lock().unwrap_or_else(|p| p.into_inner()).insert(format!("/{path}"), fault);
    }
}

fn answer(stream: TcpStream, root: &std::path::Path, faults: &Mutex<HashMap<String, Fault>>) {
    let mut reader = BufReader::new(match stream.try_clone() {
        Ok(s) => s,
        Err(_) => return,
    });
    let mut request = String::new();
    if reader.read_line(&mut request).is_err() {
        return;
    }
    // Headers, up to the blank line.
    loop {
        let mut line = String::new();
        match reader.read_line(&mut line) {
            Ok(0) | Err(_) => return,
            Ok(_) if line == "\r\n" || line == "\n" => break,
            Ok(_) => {}
        }
    }
    let mut parts = request.split_whitespace();
    let (method, path) = (parts.next().unwrap_or(""), parts.next().unwrap_or("/"));
    let fault = faults.lock().unwrap_or_else(|p| p.into_inner()).get(path).copied();
    let mut out = stream;
    let (status, body) = match fault {
        Some(Fault::Drop) => return,
        Some(Fault::Status(code)) => (code, format!("injected {code}").into_bytes()),
        None => match std::fs::read(root.join(path.trim_start_matches('/'))) {
            Ok(bytes) => (200, bytes),
            Err(_) => (404, b"not found".to_vec()),
        },
    };
    let reason = match status {
        200 => "OK",
        404 => "Not Found",
        500 => "Internal Server Error",
        _ => "Error",
    };
    let head = format!("HTTP/1.1 {status} {reason}\r\nContent-Length: {}\r\nConnection: close\r\n\r\n", body.len());
    let _ = out.write_all(head.as_bytes());
    if method != "HEAD" {
        let _ = out.write_all(&body);
    }
}
