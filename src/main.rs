fn main() {
    println!("chatterspice");
}
