//! `ssn`: command-line front end (in progress).

fn main() {
    println!("ssn: semismooth-contact (in progress)");
}
